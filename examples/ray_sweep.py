"""Evaluate the baseline on many scenarios × seeds as Ray tasks and print one JSON line per scenario.

The same script runs on a laptop and on a Ray cluster; only ``--address`` changes::

    .venv/bin/python examples/ray_sweep.py --seeds 10                        # local: ray.init()
    .venv/bin/python examples/ray_sweep.py --address auto --seeds 100        # the cluster this node belongs to
    .venv/bin/python examples/ray_sweep.py --address ray://head:10001        # a remote cluster (Ray Client)

Every episode is one Ray task running :func:`stage_sim.envs.rollouts.run_spec` (the environment is built
inside the task, so only plain data travels); the cluster's nodes need ``pip install stage_sim[ray]``
(or pass ``runtime_env``). To sweep your own policy, give run_spec's loop your policy instead of the
baseline (see :func:`stage_sim.envs.rollouts.run_parallel`).
"""

from __future__ import annotations

import argparse
import json
from typing import Any

import ray

from stage_sim.envs.rollouts import EpisodeStats, run_spec, summarise

#: What the sweep evaluates unless told otherwise: circle crossing with 4, 10 and 20 robots, and one
#: robot among random obstacles in a generated arena.
SCENARIOS: dict[str, dict[str, Any]] = {
    "circle_4": {"scenario": "circle", "n_robots": 4},
    "circle_10": {"scenario": "circle", "n_robots": 10},
    "circle_20": {"scenario": "circle", "n_robots": 20},
    "obstacles_1": {"env": "single", "scenario": "obstacles", "n_obstacles": 8},
}


def sweep(scenarios: dict[str, dict[str, Any]], seeds: list[int]) -> dict[str, list[EpisodeStats]]:
    """Every scenario × seed as one Ray task (``ray.init`` must have been called); episodes per scenario,
    in seed order."""
    episode = ray.remote(run_spec)
    refs = {name: [episode.remote(spec, seed) for seed in seeds] for name, spec in scenarios.items()}
    return {name: ray.get(futures) for name, futures in refs.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--address", default=None, help="Ray cluster address (default: start Ray on this machine)")
    parser.add_argument("--seeds", type=int, default=5, help="episodes per scenario, seeds 0..N-1")
    parser.add_argument("--scenario", action="append", choices=sorted(SCENARIOS), help="default: all")
    args = parser.parse_args()
    ray.init(address=args.address)
    try:
        chosen = {name: SCENARIOS[name] for name in args.scenario or SCENARIOS}
        for name, episodes in sweep(chosen, list(range(args.seeds))).items():
            print(json.dumps({"scenario": name, **summarise(episodes)}))
    finally:
        ray.shutdown()


if __name__ == "__main__":
    main()
