"""ravh_sim: Robot@VirtualHome for ROS 2."""
__version__ = "0.1.0"           # also in setup.py and package.xml (test_install checks they agree)
