"""ROS-free simulation core: world files, maps, kinematics, odometry, collision and ray casting.

Nothing in this package may import rclpy or any ROS message package.
"""
