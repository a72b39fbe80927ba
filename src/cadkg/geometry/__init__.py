"""Frames and poses in plain Python: rotations as ROS uses them (``frames``), rigid poses (``poses``)."""
