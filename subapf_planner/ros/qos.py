"""QoS profiles shared by the package's nodes (sensor data comes from rclpy.qos),
whether anything listens to a publisher, and which publishers a subscription cannot
hear."""

from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSCompatibility, QoSProfile, qos_check_compatible
from rclpy.topic_endpoint_info import TopicEndpointInfo

#: Published once, kept for late joiners (outcome, map, /tf_static).
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def listened(pub: Publisher) -> bool:
    """Whether anything subscribes to ``pub``: a message nobody takes is not built."""
    return pub.get_subscription_count() > 0


def type_name(msg_type: type) -> str:
    """The ROS name of a message class, e.g. ``nav_msgs/msg/Odometry``."""
    return f'{msg_type.__module__.split(".")[0]}/msg/{msg_type.__name__}'


def unheard_publishers(topic: str, msg_type: type, qos: QoSProfile,
                       publishers: list[TopicEndpointInfo]) -> dict[bytes, str]:
    """Of the ``publishers`` of ``topic`` (Node.get_publishers_info_by_topic), those whose
    messages a subscription of ``msg_type`` with ``qos`` can never receive, by endpoint
    GID: why, one line each (another message type, or an incompatible QoS, e.g. a
    best-effort publisher and a reliable subscription)."""
    wanted = type_name(msg_type)
    unheard = {}
    for pub in publishers:
        who = f'{pub.node_namespace.rstrip("/")}/{pub.node_name}'
        if pub.topic_type != wanted:
            unheard[bytes(pub.endpoint_gid)] = (
                f'{topic}: {who} publishes {pub.topic_type}, this node takes '
                f'{wanted}: none of its messages will arrive')
            continue
        compatibility, reason = qos_check_compatible(pub.qos_profile, qos)
        if compatibility == QoSCompatibility.ERROR:
            unheard[bytes(pub.endpoint_gid)] = (
                f'{topic}: the QoS {who} offers is incompatible with this '
                f"node's, none of its messages will arrive ({reason.strip()})")
    return unheard
