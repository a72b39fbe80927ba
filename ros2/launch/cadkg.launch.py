"""Launch the cadkg node: ``ros2 launch ros2/launch/cadkg.launch.py source:=/path/to/manifest.toml``.

The node runs with the Python that has cadkg and rclpy (``.venv-ros/bin/python`` by default,
or ``python:=/usr/bin/python3`` in a ROS install where cadkg is pip-installed).
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration

ROOT = Path(__file__).resolve().parents[2]


def generate_launch_description() -> LaunchDescription:
    arguments = [
        DeclareLaunchArgument("source", description="manifest.toml or store directory"),
        DeclareLaunchArgument("profile", default_value="", description="profile (default: the cell's)"),
        DeclareLaunchArgument("namespace", default_value="", description="service namespace"),
        DeclareLaunchArgument(
            "approach_distance", default_value="-1.0", description="metres; below 0: the manifest's value"
        ),
        DeclareLaunchArgument("python", default_value=str(ROOT / ".venv-ros" / "bin" / "python")),
    ]
    node = ExecuteProcess(
        cmd=[
            LaunchConfiguration("python"),
            "-m",
            "cadkg.ros_adapter",
            "--ros-args",
            "-p",
            ["source:='", LaunchConfiguration("source"), "'"],
            "-p",
            ["profile:='", LaunchConfiguration("profile"), "'"],
            "-p",
            ["namespace:='", LaunchConfiguration("namespace"), "'"],
            "-p",
            ["approach_distance:=", LaunchConfiguration("approach_distance")],
        ],
        output="screen",
    )
    return LaunchDescription([*arguments, node])
