"""Ray casting on the world grid as Stage does it (its integer walk, :mod:`stage_sim.sensing.stage_walk`):
every beam of every robot, static obstacles and robot bodies.

Pure array code with no notion of robots' kinematics: :mod:`stage_sim.sim` places the rays and reads the
ranges. Imports only :mod:`stage_sim.maps` and :mod:`stage_sim.worldfile`.
"""
