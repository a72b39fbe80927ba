"""ros2/cadkg_interfaces builds with colcon, as in a ROS workspace, and its Python types load.

colcon comes pinned in ros2/requirements.txt; the underlay is the venv's ROS wheels.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.ros.live.conftest import ROOT


def test_colcon_builds_the_interface_package(tmp_path: Path) -> None:
    venv = Path(sys.prefix)
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "cadkg_interfaces").symlink_to(ROOT / "ros2" / "cadkg_interfaces")
    env = {
        **os.environ,
        "PATH": f"{venv / 'bin'}:{os.environ.get('PATH', '')}",
        "AMENT_PREFIX_PATH": str(venv),
        "CMAKE_PREFIX_PATH": str(venv),
    }
    build = subprocess.run(
        [str(venv / "bin" / "colcon"), "build", "--packages-select", "cadkg_interfaces",
         "--event-handlers", "console_direct-",
         "--cmake-args", f"-DPython3_EXECUTABLE={sys.executable}", "-DPython3_FIND_STRATEGY=LOCATION",
         "-DBUILD_TESTING=OFF"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=1500, check=False,
    )  # fmt: skip
    assert build.returncode == 0, (build.stdout + build.stderr)[-4000:]
    install = tmp_path / "install" / "cadkg_interfaces"
    site = next(install.glob("lib/python3*/site-packages"))
    probe = (
        "import cadkg_interfaces.srv as s; print(s.__file__);"
        "print(sorted(s.GuideInfo.Response.get_fields_and_field_types()))"
    )
    libraries = f"{install / 'lib'}:{os.environ.get('LD_LIBRARY_PATH', '')}"
    loaded = subprocess.run(
        [sys.executable, "-c", probe],
        env={**env, "PYTHONPATH": str(site), "LD_LIBRARY_PATH": libraries},
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert loaded.returncode == 0, loaded.stderr[-3000:]
    where, fields = loaded.stdout.splitlines()[:2]
    assert where.startswith(str(site))  # this build, not the one of scripts/ros-setup.sh
    assert "key_frame" in fields and "key_corner_frame" in fields
