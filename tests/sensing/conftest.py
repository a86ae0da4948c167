"""Every ray-casting test runs against both implementations (the numpy reference and the numba kernels)."""

from __future__ import annotations

from functools import partial

import pytest

from stage_sim.backend import KERNELS
from stage_sim.sensing.casters import make_caster


@pytest.fixture(params=KERNELS)
def kernels(request) -> str:
    """"numba" or "numpy"."""
    return request.param


@pytest.fixture
def new_caster(kernels):
    """``new_caster(occupied, resolution, origin_xy)``: a caster of the implementation under test."""
    return partial(make_caster, kernels=kernels)
