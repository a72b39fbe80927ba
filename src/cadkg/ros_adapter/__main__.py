"""``python -m cadkg.ros_adapter SOURCE [--profile P] [--namespace NS] [--ros-args ...]``."""

import sys

from cadkg.ros_adapter.node import main

sys.exit(main())
