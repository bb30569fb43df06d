"""Data-collection behaviours (Wanderer, Grid): plain-Python state machines over a drivable robot.

They drive anything with a ``pose`` and ``set_command`` (a simulated Robot in tests, a ROS adapter in
the behaviour nodes) through the PathFollower, and return the captures they want taken.
"""
