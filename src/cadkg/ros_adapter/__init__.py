"""ROS 2 access to a cell: the only package that imports rclpy (in :mod:`.node`).

:mod:`.convert` is plain Python and imports without ROS.
"""
