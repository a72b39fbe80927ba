"""ROS 2 adapter (rclpy): the only part of cadkg that imports rclpy. Not built yet."""

__all__: list[str] = []
