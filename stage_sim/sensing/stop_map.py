"""Which regions end Stage's jumps over empty regions: a byte per region, with a margin of empty ones around.

The compiled walk (:mod:`stage_sim.sensing.traversal`) jumps from region to region until one holds a block:
static (the tile grid's slot is set) or, in a cast with robots, a robot's (the robot layer marks its region).
Asked of the slots and the robot layer, that is two int32 loads and four bounds tests a jump, the most
frequent step of a long beam at a fine resolution (95 jumps a beam on the 1 mm RL world of
``benchmarks/worlds.py``). This map answers it with one byte, and with no bounds test for a ray that cannot
leave the margin: the map reaches :attr:`StopMap.pad` regions beyond the tile grid on every side, more than
the longest beam cast so far. The robots' regions are set for the length of a cast and reset after it
(:func:`mark_robot_regions`, called by :func:`stage_sim.sensing.traversal.cast_serial`). A region set here that
holds nothing would cost the walk a look at it and change no answer (the walk finds it empty and jumps on from
where it stood); one left unset that holds a block would be jumped over, so the map is the static regions and
the robots' exactly.

What it costs: (R + 2·pad) × (C + 2·pad) bytes for R × C regions: 1.4 MB on the 30 m × 30 m world at 1 mm
with 4 m beams. The map stays under :data:`STOP_MAP_LIMIT` bytes (a smaller margin then; rays that could
leave it look their regions up with bounds tests instead, as do all rays of a world too large for it).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.maps.tiles import TILE

#: Largest stop map kept, in bytes (one per region): 64 MB, the regions of 6.6 × 10¹⁰ cells.
STOP_MAP_LIMIT = 64_000_000
#: Regions of margin beyond a beam's reach in cells / TILE: the walk's own slack (the last region it looks at
#: may lie a region past its steps; truncation toward zero and the origin's own region) and one to spare.
_SPARE = 5


class StopMap:
    """The stop map of one tile grid's slots; :meth:`fitted` grows its margin to the beams cast."""

    def __init__(self, slots: np.ndarray) -> None:
        self._slots = slots
        self._largest: int | None = None  # the widest margin allowed, asked at every cast: worked out at the first
        self.pad = -1  #: regions of margin on each side (-1: not built yet)
        self.cells = np.zeros((1, 1), dtype=np.uint8)  #: (R + 2·pad, C + 2·pad) 1 where a jump stops

    def fitted(self, reach_cells: float) -> tuple[np.ndarray, int]:
        """(map, pad) with a margin for beams of up to ``reach_cells`` cells (rebuilt only to grow it)."""
        rows, cols = self._slots.shape
        if self._largest is None:
            self._largest = _largest_pad(rows, cols)
        want = min(int(1.5 * reach_cells) // TILE + _SPARE, self._largest)
        if want > self.pad:
            cells = np.zeros((rows + 2 * want, cols + 2 * want), dtype=np.uint8)
            cells[want:want + rows, want:want + cols] = self._slots >= 0
            self.cells, self.pad = cells, want
        return self.cells, self.pad


def _largest_pad(rows: int, cols: int) -> int:
    """The widest margin keeping (rows + 2·pad)(cols + 2·pad) within :data:`STOP_MAP_LIMIT`; -1 if none does
    (the map stays then the 1 × 1 placeholder with margin -1, which no ray fits in)."""
    if rows * cols > STOP_MAP_LIMIT:
        return -1
    pad = int((-(rows + cols) + math.sqrt((rows + cols) ** 2 + 4 * (STOP_MAP_LIMIT - rows * cols))) / 4)
    while pad > 0 and (rows + 2 * pad) * (cols + 2 * pad) > STOP_MAP_LIMIT:
        pad -= 1
    return pad


@numba.njit(cache=True, nogil=True)
def mark_robot_regions(stops, pad, slots, marked, robots_stop):
    """Set the stop map at the robot layer's regions (``marked``, flat in the region grid) when
    ``robots_stop``, else reset them to the static regions' value."""
    if pad < 0:
        return
    rw = slots.shape[1]
    for f in marked:
        r, c = f // rw, f % rw
        stops[r + pad, c + pad] = 1 if robots_stop or slots[r, c] >= 0 else 0
