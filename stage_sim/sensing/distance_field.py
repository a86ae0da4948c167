"""Free-space certificates for both ray casters: the largest free square ahead of a cell, within its tile.

For each cell ``c`` of a tile and each of the four diagonal quadrants ``q = (sx < 0) + 2·(sy < 0)``, the
side ``k`` of the largest free square that has ``c`` as its corner and extends towards ``(sx, sy)``
*without leaving the tile*: the cells ``c + (sx·i, sy·j)``, ``0 <= i, j < k``, are all free and in the
tile, and ``k = 0`` iff ``c`` is occupied. Cells beyond the tile count as occupied, so a jump through the
square never leaves the tile (Stage's region): the walk takes the region border one step at a time and
looks at the next region afresh. A ray moving towards that quadrant cannot leave the square before it has
travelled ``k`` cells along one axis, wherever it starts inside ``c``.

Computed by the classic "largest square" recurrence ``k(c) = 1 + min(k(c+x), k(c+y), k(c+x+y))``, one row
of every tile at a time (the row recurrence is a reversed running minimum, so a row is a handful of numpy
calls for all tiles and quadrants together). Static tiles: 32 × 32 cells, 4 KB per tile (uint8 per cell
and quadrant); robot block tiles: 4 × 4 blocks, 64 B.
"""

from __future__ import annotations

import numpy as np

#: Largest square side a caller may treat as "no limit" (every tile square is at most a tile side).
SQUARE_CAP = 255


def tile_square_fields(occupied: np.ndarray) -> np.ndarray:
    """(T, 4, S, S) uint8 square sides of tiles ``occupied`` (T, S, S) bool, ``[tile, q, row, col]``."""
    occ = np.asarray(occupied, dtype=bool)
    t, s = occ.shape[0], occ.shape[1]
    # Every quadrant turned to extend towards +x / +y: mirrored in x when sx < 0, in y when sy < 0.
    flipped = np.stack([occ, occ[:, :, ::-1], occ[:, ::-1, :], occ[:, ::-1, ::-1]], axis=1).reshape(4 * t, s, s)
    out = np.empty((4 * t, s, s), dtype=np.uint8)
    col = np.arange(s + 1, dtype=np.int32)
    # prev: sides of the row above (y + 1); one extra column, beyond the tile: occupied (side 0).
    prev = np.zeros((4 * t, s + 1), dtype=np.int32)
    cand = np.empty((4 * t, s + 1), dtype=np.int32)
    cand[:, s] = s
    for y in range(s - 1, -1, -1):
        # Free cell: k(x) = 1 + min(m(x), k(x+1)) with m(x) = min(k_above(x), k_above(x+1)); an
        # occupied cell has k = 0. Unrolled, k(x) = min_{x' >= x} cand(x') - x with
        # cand(x') = x' (occupied) or m(x') + 1 + x' (free): a reversed running minimum.
        np.minimum(prev[:, :s], prev[:, 1:], out=cand[:, :s])
        cand[:, :s] += col[:s] + 1
        np.copyto(cand[:, :s], col[:s], where=flipped[:, y])
        prev = np.minimum.accumulate(cand[:, ::-1], axis=1)[:, ::-1] - col
        out[:, y] = prev[:, :s]
    out = out.reshape(t, 4, s, s)
    return np.ascontiguousarray(np.stack(
        [out[:, 0], out[:, 1, :, ::-1], out[:, 2, ::-1, :], out[:, 3, ::-1, ::-1]], axis=1))
