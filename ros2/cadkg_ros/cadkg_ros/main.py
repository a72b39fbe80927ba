"""``ros2 run cadkg_ros cadkg_node --ros-args -p source:=/path/to/manifest.toml``."""

import sys


def main() -> None:
    """Run cadkg's node with this process's arguments (``--ros-args`` included)."""
    from cadkg.ros_adapter.node import main as node_main

    sys.exit(node_main(sys.argv[1:]))
