"""``python -m stage_sim.envs.warm_up``: compile every numba kernel once into the disk cache (``make setup`` runs
it): the simulation's (:mod:`stage_sim.sim.warm_up`) and the RL environments' own (commands, observations and
rewards, free space and placement), so that neither the first simulation nor the first env a user makes waits
for the compiler (the envs' kernels took some 11 s on a cold cache)."""

from __future__ import annotations

import logging
import os

from stage_sim.backend import KERNELS_ENV, numba_available
from stage_sim.envs.navigate import NavigateEnv
from stage_sim.envs.vector import NavigateVectorEnv
from stage_sim.envs.worlds import RobotBody
from stage_sim.sim import warm_up


def warm() -> None:
    """Run every kernel once (compiling what the cache lacks): the simulation's, then an obstacles episode of a
    small env with continuous and with discrete actions, stepped (in one call, and part by part) and reset, and a
    small vector env's steps, on the compiled kernels."""
    warm_up.warm()
    if not numba_available():
        return
    asked = os.environ.get(KERNELS_ENV)
    os.environ[KERNELS_ENV] = "numba"  # the envs' simulations take the kernels from here
    try:
        for discrete in (False, True):
            env = NavigateEnv(scenario="obstacles", arena_size=6.0, n_obstacles=2, discrete=discrete,
                              body=RobotBody(laser_samples=16))
            env.reset(seed=0)
            for _ in range(2):
                env.step(env.action_space.sample())
            # a step not made in one call (the kernels it is made of): a simulation's watchdog is applied apart
            env.task.sim.watchdog_timeout = 60.0
            env.step(env.action_space.sample())
            env.reset()  # an episode's free space, derived from the first one's
        # a vector env's worlds, stepped and scored together (the kernels take the batch's arrays)
        worlds = NavigateVectorEnv(2, scenario="obstacles", arena_size=6.0, n_obstacles=2,
                                   body=RobotBody(laser_samples=16))
        worlds.reset(seed=0)
        for _ in range(2):
            worlds.step(worlds.action_space.sample())
    finally:
        if asked is None:
            del os.environ[KERNELS_ENV]
        else:
            os.environ[KERNELS_ENV] = asked


if __name__ == "__main__":
    logging.basicConfig(format="%(message)s")
    warm()
