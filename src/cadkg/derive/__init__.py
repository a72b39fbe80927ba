"""Facts derived from what the readers found: frames and poses (more to come per use case)."""

from cadkg.derive.frames import Quaternion, normalize_quaternion, quaternion_from_rpy

__all__ = ["Quaternion", "normalize_quaternion", "quaternion_from_rpy"]
