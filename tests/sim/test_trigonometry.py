"""The compiled fused step computes the cosines and sines of headings in numba (libm's), where the
role-by-role kernels and the numpy reference take numpy's: a step is the same bit for bit only while the two
agree on every float64. They do with numpy 2.x, whose float64 ``cos`` and ``sin`` are libm's (its SIMD loops
cover float32); this test says so at once on a machine or a numpy where they would not."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=False)
def _compiled_trig(angles: np.ndarray, out: np.ndarray) -> None:
    for i in range(angles.size):
        out[0, i], out[1, i] = math.cos(angles[i]), math.sin(angles[i])


def test_numba_cos_and_sin_are_numpys_bit_for_bit() -> None:
    rng = np.random.default_rng(7)
    angles = np.concatenate([
        rng.uniform(-math.pi, math.pi, 200_000),  # headings
        rng.uniform(-1e3, 1e3, 100_000),  # far from the wrapped range
        np.array([0.0, -0.0, math.pi, -math.pi, math.pi / 2, -math.pi / 2, 1e-300, 5e-324]),
        np.nextafter(np.array([math.pi / 4, math.pi / 2, math.pi]), 0.0),
    ])
    compiled = np.empty((2, angles.size))
    _compiled_trig(angles, compiled)
    assert np.array_equal(compiled[0].view(np.int64), np.cos(angles).view(np.int64))
    assert np.array_equal(compiled[1].view(np.int64), np.sin(angles).view(np.int64))
