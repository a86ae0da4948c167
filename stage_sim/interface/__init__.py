"""stageros' ROS interface as plain data, without ROS: what the ROS layer publishes and the bags record.

``topics`` is the one registry of the topics stageros publishes and subscribes (name rule, message type, QoS,
per robot or world-wide, the values each step gives them); ``names`` the per-robot name rules; ``frames`` the
frames and fixed TF edges; ``fields`` the message field values; ``qos`` the QoS profiles. :mod:`stage_sim.ros`
turns these into rclpy messages and profiles, :mod:`stage_sim.bags` into rosbags' classes.
"""
