"""A wander session in the core alone: what ``launch_scripts/reactive.py --speedup 0`` runs, without ROS.

The lockstep session steps the world, then waits until every wanderer has answered the new scan; here the
core simulation is stepped the same way and :class:`~stage_sim.runs.driver.WanderDriver` hands each
wanderer exactly what the ``wander`` node receives, so a seed gives the same summaries as through the nodes
(``tests/ros/test_launch_scripts.py`` holds the two side by side) for a fraction of the CPU: no DDS, no
messages. ``benchmarks/wander_sweep.py --core`` runs many seeds of it.
"""

from __future__ import annotations

from stage_sim.runs.driver import WanderDriver
from stage_sim.runs.pacing import END_TOLERANCE_S, WATCHDOG_S, run_end
from stage_sim.runs.stats import RunStats
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.description import WorldDescription


def wander_summaries(description: WorldDescription, seed: int | None, seconds: float) -> list[dict]:
    """Step the world ``seconds`` sim seconds (or to its quit_time) with a wanderer per laser-equipped
    robot; one JSON-ready summary per robot, as the launch scripts print them."""
    sim = Simulation(description, seed=seed, watchdog_timeout=WATCHDOG_S)
    driver, stats = WanderDriver(sim, seed), RunStats(sim)
    end = run_end(description.settings.quit_time, seconds)
    while sim.sim_time < end - END_TOLERANCE_S:
        sim.step()
        stats.update()
        driver.decide()
    return stats.summaries()
