"""The simulation: robots, kinematics, odometry error, collision and stall, rangers, the fixed-step clock.

:class:`~stage_sim.sim.simulation.Simulation` is the core's one entry point; it uses :mod:`stage_sim.sensing`
for the lasers and :mod:`stage_sim.maps` for the static world.
"""
