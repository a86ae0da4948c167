"""ROS 2 bags (MCAP) of a running simulation, written without ROS: what stageros publishes, topic for topic.

``BagRecorder`` (recorder.py) copies a simulation step by step (step_state.py) into memory it shares with its
writer process (slots.py; writer.py, a fresh interpreter) a batch of steps at a time; the container (container.py,
foxglove-sdk's MCAP writer) and the messages (messages.py, ``rosbags``' classes and CDR, refilled in place each
step by layouts.py through step_messages.py) follow what ``ros2 bag record -s mcap`` writes; topics, names and
field values come from :mod:`stage_sim.interface`, as the ROS layer's do; recover.py rescues a file cut short.
"""
