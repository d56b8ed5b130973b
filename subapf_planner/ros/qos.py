"""QoS profiles shared by the package's nodes (sensor data comes from rclpy.qos), and
whether anything listens to a publisher."""

from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile

#: Published once, kept for late joiners (outcome, map, /tf_static).
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def listened(pub: Publisher) -> bool:
    """Whether anything subscribes to ``pub``: a message nobody takes is not built."""
    return pub.get_subscription_count() > 0
