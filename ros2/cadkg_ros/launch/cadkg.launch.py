"""``ros2 launch cadkg_ros cadkg.launch.py source:=/path/to/manifest.toml [namespace:=cell2] ...``

Starts ``cadkg_node`` with the cell (a manifest or a store directory) as its ``source``. The
``namespace`` launch argument is the node's namespace: every service, and the markers topic,
move under it (``/cell2/gearbox_handler/cad_service``); frames stay on ``/tf_static``.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue

ARGUMENTS = (
    ("source", None, "manifest.toml or store directory of the cell"),
    ("profile", "", "use case (default: the cell's [cell] profile)"),
    ("namespace", "", "the node's namespace; every service and the markers move under it"),
    ("approach_distance", "-1.0", "metres; below 0: the manifest's value"),
    ("marker_period", "2.0", "seconds between two publications of the markers; 0: once, latched"),
    ("allow_assign", "false", "open a store directory writable, so the assign service can keep its edits"),
    ("max_query_memory", "1024", "MiB one sparql query may take; 0: no limit"),
)


def generate_launch_description() -> LaunchDescription:
    declared = [
        DeclareLaunchArgument(name, description=text)
        if default is None
        else DeclareLaunchArgument(name, default_value=default, description=text)
        for name, default, text in ARGUMENTS
    ]
    node = Node(
        package="cadkg_ros",
        executable="cadkg_node",
        name="cadkg",
        namespace=LaunchConfiguration("namespace"),
        output="screen",
        parameters=[
            {
                "source": LaunchConfiguration("source"),
                "profile": LaunchConfiguration("profile"),
                "approach_distance": ParameterValue(
                    LaunchConfiguration("approach_distance"), value_type=float
                ),
                "marker_period": ParameterValue(LaunchConfiguration("marker_period"), value_type=float),
                "allow_assign": ParameterValue(LaunchConfiguration("allow_assign"), value_type=bool),
                "max_query_memory": ParameterValue(LaunchConfiguration("max_query_memory"), value_type=int),
            }
        ],
    )
    return LaunchDescription([*declared, node])
