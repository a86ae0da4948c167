"""The thin ROS 2 layer over the ROS-free core: nodes, message conversions, names, TF and clock."""
