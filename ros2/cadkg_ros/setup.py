"""The cadkg node as a ROS 2 package (ament_python): ``ros2 run cadkg_ros cadkg_node`` and
``ros2 launch cadkg_ros cadkg.launch.py``. The node itself is cadkg's (``cadkg.ros_adapter``),
installed with pip into the Python that ROS uses."""

from setuptools import setup

PACKAGE = "cadkg_ros"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=[PACKAGE],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", ["launch/cadkg.launch.py"]),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="cadkg",
    maintainer_email="cadkg@example.org",
    description="The cadkg node: a cell's knowledge graph as ROS 2 services, tf frames and markers.",
    license="Apache-2.0",
    entry_points={"console_scripts": ["cadkg_node = cadkg_ros.main:main"]},
)
