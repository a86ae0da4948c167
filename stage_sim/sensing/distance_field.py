"""Free-space certificates for the numpy ray caster: the largest free square ahead of a cell, within its tile.

For each cell ``c`` of a tile and each of the four diagonal quadrants ``q = (sx < 0) + 2·(sy < 0)``, the
side ``k`` of the largest free square that has ``c`` as its corner and extends towards ``(sx, sy)``
*without leaving the tile*: the cells ``c + (sx·i, sy·j)``, ``0 <= i, j < k``, are all free and in the
tile, and ``k = 0`` iff ``c`` is occupied. Cells beyond the tile count as occupied, so a jump through the
square never leaves the tile (Stage's region): the walk takes the region border one step at a time and
looks at the next region afresh. A ray moving towards that quadrant cannot leave the square before it has
travelled ``k`` cells along one axis, wherever it starts inside ``c``.

Computed by the classic "largest square" recurrence ``k(c) = 1 + min(k(c+x), k(c+y), k(c+x+y))``, one row
of every tile at a time (the row recurrence is a running minimum, so a row is a handful of numpy calls for
many tiles and all quadrants together). Static tiles: 32 × 32 cells, 4 KB per tile (uint8 per cell
and quadrant); robot block tiles: 4 × 4 blocks, 64 B.
"""

from __future__ import annotations

import numpy as np

#: Largest square side a caller may treat as "no limit" (every tile square is at most a tile side).
SQUARE_CAP = 255


#: Tiles per numpy pass (bounds the temporaries to a few tens of MB).
CHUNK_TILES = 4096


def tile_square_fields(occupied: np.ndarray) -> np.ndarray:
    """(T, 4, S, S) uint8 square sides of tiles ``occupied`` (T, S, S) bool, ``[tile, q, row, col]``."""
    occ = np.asarray(occupied, dtype=bool)
    out = np.empty((occ.shape[0], 4, occ.shape[1], occ.shape[2]), dtype=np.uint8)
    for start in range(0, occ.shape[0], CHUNK_TILES):
        out[start:start + CHUNK_TILES] = _chunk_fields(occ[start:start + CHUNK_TILES])
    return out


def _chunk_fields(occ: np.ndarray) -> np.ndarray:
    t, s = occ.shape[0], occ.shape[1]
    # Every quadrant turned so that its squares extend towards lower indices (mirrored in x when sx > 0, in
    # y when sy > 0): rows are then swept upwards and each row's recurrence is a forward running minimum.
    turned = np.stack([occ[:, ::-1, ::-1], occ[:, ::-1, :], occ[:, :, ::-1], occ], axis=1).reshape(4 * t, s, s)
    out = np.empty((4 * t, s, s), dtype=np.uint8)
    x = np.arange(-1, s, dtype=np.int32)  # column 0 of the work rows: beyond the tile, occupied (side 0)
    prev = np.zeros((4 * t, s + 1), dtype=np.int32)
    cand = np.empty((4 * t, s + 1), dtype=np.int32)
    for y in range(s):
        # Free cell: k(x) = 1 + min(m(x), k(x-1)) with m(x) = min(k_below(x), k_below(x-1)); an occupied cell
        # has k = 0. Unrolled, k(x) = x + min_{x' <= x} (cand(x') - x') with cand(x') = 0 (occupied) or
        # m(x') + 1 (free): a running minimum.
        np.minimum(prev[:, 1:], prev[:, :-1], out=cand[:, 1:])
        cand[:, 1:] += 1
        np.copyto(cand[:, 1:], 0, where=turned[:, y])
        cand[:, 0] = 0
        cand -= x
        np.minimum.accumulate(cand, axis=1, out=cand)
        cand += x
        out[:, y] = cand[:, 1:]
        prev, cand = cand, prev
    out = out.reshape(t, 4, s, s)
    return np.stack([out[:, 0, ::-1, ::-1], out[:, 1, ::-1, :], out[:, 2, :, ::-1], out[:, 3]], axis=1)
