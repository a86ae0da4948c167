"""stage_sim: a pure-Python re-implementation of Stage's stageros for ROS 2.

The simulation core (:mod:`stage_sim.core`) runs without ROS; :mod:`stage_sim.ros` holds the rclpy nodes.
"""

__version__ = "0.1.0"
