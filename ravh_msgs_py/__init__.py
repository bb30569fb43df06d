"""ravh_msgs_py: the interface of ravh_sim that clients import — names, the query language, a client.

Plain Python (the ROS client in :mod:`ravh_msgs_py.client` imports rclpy lazily), so tools can use
the query language and the topic/frame names without the simulator installed.
"""
