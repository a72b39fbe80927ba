"""ROS 2 access to a cell: the only package that imports rclpy (in :mod:`.node`).

:mod:`.convert` and :mod:`.frames` are plain Python and import without ROS.
"""
