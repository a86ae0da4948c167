"""The thin ROS 2 layer over :mod:`stage_sim.core`: nodes, message conversions, names, TF and clock."""
