"""The cadkg node as a ROS 2 executable (see ``cadkg_ros.main``)."""
