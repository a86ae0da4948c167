"""ROS 2 bags (MCAP) of a running simulation, written without ROS: what stageros publishes, topic for topic.

``BagRecorder`` (recorder.py) records a simulation step by step from a writer thread; the container
(container.py, the ``mcap`` library) and the messages (messages.py, ``rosbags``' classes and CDR) follow what
``ros2 bag record -s mcap`` writes; names.py and fields.py describe stageros' names and field values for both
the ROS layer and the bags; recover.py rescues a file cut short.
"""
