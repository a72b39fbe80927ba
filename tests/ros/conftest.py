"""The live ROS tests (tests/ros/live) run only in .venv-ros, started by test_live.py."""

from __future__ import annotations

import os

collect_ignore = [] if os.environ.get("CADKG_ROS_LIVE") == "1" else ["live"]
