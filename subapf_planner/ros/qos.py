"""QoS profiles shared by the package's nodes (sensor data comes from rclpy.qos)."""

from rclpy.qos import DurabilityPolicy, QoSProfile

#: Published once, kept for late joiners (outcome, map, /tf_static).
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
