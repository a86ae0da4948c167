"""The reactive wanderer: from one laser reading and an odometry pose to the next velocity command.

It knows nothing of the simulation (the ``wander`` ROS node and :mod:`stage_sim.runs` feed it), so the
same code drives a simulated robot and, through ROS, anything that publishes a scan.
"""
