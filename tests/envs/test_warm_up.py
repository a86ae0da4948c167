"""``make setup``'s warm-up runs every compiled kernel of the RL envs, so that no user's first env waits for the
compiler: a kernel added to the envs and not to the warm-up fails here."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from stage_sim.backend import numba_available

# In a fresh interpreter (the test process has run the kernels already): the warm-up, then the kernels Python
# calls (the private ones are compiled into their callers) that it never ran.
PROBE = """
import json, numba
from stage_sim.envs import free_space_kernels, step_kernels, warm_up
warm_up.warm()
kernels = {f"{module.__name__}.{name}": value for module in (step_kernels, free_space_kernels)
           for name, value in vars(module).items()
           if isinstance(value, numba.core.registry.CPUDispatcher) and not name.startswith("_")}
print(json.dumps({"kernels": sorted(kernels), "cold": sorted(n for n, k in kernels.items() if not k.signatures)}))
"""


@pytest.mark.skipif(not numba_available(), reason="numba cannot load on this platform: there is nothing to warm")
def test_the_warm_up_runs_every_kernel_of_the_envs() -> None:
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=300, check=True)
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert "stage_sim.envs.step_kernels.observe_and_score" in found["kernels"]
    assert "stage_sim.envs.free_space_kernels.add_bodies_into" in found["kernels"]
    assert found["cold"] == []
