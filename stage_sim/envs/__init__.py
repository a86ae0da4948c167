"""Reinforcement-learning environments over the simulation core (the ``stage_sim[rl]`` extra).

* :class:`NavigateEnv`, registered as ``stage_sim/Navigate-v0`` when this package is imported: one robot of
  any Stage world reaches goals (Gymnasium);
* :class:`NavigateVectorEnv`, that id's vector entry point: N one-robot worlds stepped together
  (``gymnasium.make_vec("stage_sim/Navigate-v0", num_envs=N, vectorization_mode="vector_entry_point")``);
* :class:`NavigateParallelVectorEnv`: the same N worlds as one PettingZoo env, agent ``world_<i>`` each;
* :class:`NavigateParallelEnv`: N robots of one world, all stepped by one simulation step (PettingZoo);
* :class:`GoalSeeker`: a scripted reactive baseline, and :mod:`stage_sim.envs.rollouts` to evaluate it.
"""

from __future__ import annotations

import gymnasium

from stage_sim.envs.baseline import GoalSeeker
from stage_sim.envs.navigate import NavigateEnv
from stage_sim.envs.parallel import NavigateParallelEnv
from stage_sim.envs.parallel_vector import NavigateParallelVectorEnv
from stage_sim.envs.task import RewardConfig
from stage_sim.envs.vector import NavigateVectorEnv
from stage_sim.envs.worlds import RobotBody

ENV_ID = "stage_sim/Navigate-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(ENV_ID, entry_point="stage_sim.envs.navigate:NavigateEnv",
                       vector_entry_point="stage_sim.envs.vector:NavigateVectorEnv")

__all__ = [
    "ENV_ID", "GoalSeeker", "NavigateEnv", "NavigateParallelEnv", "NavigateParallelVectorEnv", "NavigateVectorEnv",
    "RewardConfig", "RobotBody"]
