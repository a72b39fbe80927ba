"""ros2/cadkg_interfaces builds with colcon, as in a ROS workspace, and its Python types load.

colcon comes pinned in ros2/requirements.txt; the underlay is the venv's ROS wheels.
scripts/ros-setup.sh (the test command's set-up) builds the package that way, merged into
build/ros/install, the build every live test loads its types from; the first test checks that
build and its outcome rather than compiling the 74 interfaces a second time (3 to 4 minutes on
a loaded 2-core machine). The build is the one rclpy needs (``CADKG_INTERFACES_PYTHON_ONLY=ON``);
compiling the C++ type supports of the default build took 12 of the 14 minutes of the whole
live run, so the default is configured and its C++ headers generated, not compiled
(docs/ros.md).
"""

from __future__ import annotations

import ast
import functools
import subprocess
import sys
from pathlib import Path

from tests.ros.live.conftest import ROOT, underlay_environment

PACKAGE = ROOT / "ros2" / "cadkg_interfaces"
PREFIX = ROOT / "build" / "ros" / "install"
CPP_TYPE_SUPPORTS = (
    "cadkg_interfaces__rosidl_typesupport_cpp",
    "cadkg_interfaces__rosidl_typesupport_fastrtps_cpp",
    "cadkg_interfaces__rosidl_typesupport_introspection_cpp",
)


BUILT = ROOT / "build" / "ros" / "colcon-build" / "cadkg_interfaces"
LOG = ROOT / "build" / "ros" / "colcon-log" / "latest_build" / "logger_all.log"
PYTHON_ONLY = "-DCADKG_INTERFACES_PYTHON_ONLY=ON"
UNITY = "-DCADKG_INTERFACES_UNITY=ON"
# What the unity build compiles as batches, each one object of a Unity/ folder of its target.
UNITY_TARGETS = (
    "cadkg_interfaces__rosidl_typesupport_c",
    "cadkg_interfaces__rosidl_typesupport_fastrtps_c",
    "cadkg_interfaces__rosidl_typesupport_introspection_c",
    "cadkg_interfaces__rosidl_generator_py",
)


@functools.cache
def _setup_cmake_args() -> tuple[str, ...]:
    """The arguments scripts/ros-setup.sh gave cmake, as colcon recorded them for the package."""
    recorded = ast.literal_eval((BUILT / "cmake_args.last").read_text(encoding="utf-8"))
    assert isinstance(recorded, list) and all(isinstance(arg, str) for arg in recorded), recorded
    return tuple(recorded)


def test_colcon_builds_the_interface_package() -> None:
    # colcon's own records of the set-up's build: a merged install, the Python-only build, and
    # the return code colcon keeps for each package it built (what
    # --packages-select-build-failed reads): 0, as a failed build leaves another.
    assert (PREFIX / ".colcon_install_layout").read_text(encoding="utf-8").strip() == "merged"
    assert PYTHON_ONLY in _setup_cmake_args() and UNITY in _setup_cmake_args()
    for target in UNITY_TARGETS:
        assert list((BUILT / "CMakeFiles" / f"{target}.dir" / "Unity").glob("unity_*.o")), target
    assert not (BUILT / "CMakeFiles" / "cadkg_interfaces__rosidl_generator_c.dir" / "Unity").exists()
    rc = (BUILT / "colcon_build.rc").read_text(encoding="utf-8").strip()
    assert rc == "0", LOG.read_text(encoding="utf-8")[-3000:]
    assert (PREFIX / "share" / "ament_index" / "resource_index" / "packages" / "cadkg_interfaces").is_file()
    probe = (
        "import cadkg_interfaces.srv as s; print(s.__file__);"
        "print(sorted(s.GuideInfo.Response.get_fields_and_field_types()))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", probe], env=underlay_environment(),
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert loaded.returncode == 0, loaded.stderr[-3000:]
    where, fields = loaded.stdout.splitlines()[:2]
    assert where.startswith(str(PREFIX / "lib"))  # colcon's install, not a source tree
    assert "key_frame" in fields and "key_corner_frame" in fields
    built = list((PREFIX / "lib").glob("libcadkg_interfaces__*"))
    assert built, "no type support of cadkg_interfaces in the install"
    assert not [lib for lib in built if "cpp" in lib.name], "the Python-only build compiled C++ type supports"


def test_the_default_build_has_the_cpp_type_supports_and_their_headers(tmp_path: Path) -> None:
    env = underlay_environment()
    default = [arg for arg in _setup_cmake_args() if arg not in (PYTHON_ONLY, UNITY)]
    configured = subprocess.run(
        ["cmake", "-S", str(PACKAGE), "-B", str(tmp_path), *default],
        env=env, capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert configured.returncode == 0, (configured.stdout + configured.stderr)[-4000:]
    targets = subprocess.run(
        ["cmake", "--build", str(tmp_path), "--target", "help"],
        env=env, capture_output=True, text=True, timeout=120, check=True,
    ).stdout  # fmt: skip
    listed = {line.removeprefix("... ").strip() for line in targets.splitlines()}
    assert set(CPP_TYPE_SUPPORTS) <= listed, sorted(name for name in listed if "cadkg_interfaces__" in name)
    headers = subprocess.run(
        ["cmake", "--build", str(tmp_path), "--target", "cadkg_interfaces__cpp"],
        env=env, capture_output=True, text=True, timeout=900, check=False,
    )  # fmt: skip
    assert headers.returncode == 0, (headers.stdout + headers.stderr)[-4000:]
    generated = tmp_path / "rosidl_generator_cpp" / "cadkg_interfaces"
    expected = {path.stem for path in (*PACKAGE.glob("msg/*.msg"), *PACKAGE.glob("srv/*.srv"))}
    written = {path.stem.replace("_", "") for path in generated.glob("*/*.hpp")}
    assert {name.lower() for name in expected} <= written
