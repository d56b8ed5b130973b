"""rosbag2-compatible MCAP writing: CDR messages with ``ros2msg`` schemas (profile ros2).

Schemas are the message definitions as ``ros2 bag record -s mcap`` stores
them: the type's .msg text, then each nested type after a line of 80 '='
and ``MSG: pkg/Type``. The .msg files come from the installed interface
packages (share/<pkg>/msg), found through AMENT_PREFIX_PATH or the Python prefix.
"""

from __future__ import annotations

import os
from pathlib import Path
import re
import sys

from mcap.writer import CompressionType, Writer

SEPARATOR = '=' * 80
PRIMITIVES = {'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16',
              'uint16', 'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring'}
#: QoS advertised in channel metadata (rosbag2 requires the key; YAML list of profiles).
DEFAULT_QOS = ('- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n'
               '  deadline:\n    sec: 9223372036\n    nsec: 854775807\n'
               '  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n'
               '  liveliness: 1\n  liveliness_lease_duration:\n    sec: 9223372036\n'
               '    nsec: 854775807\n  avoid_ros_namespace_conventions: false\n')


class RecorderError(RuntimeError):
    """A message definition could not be found, or the file could not be written."""


def _share_dirs() -> list[Path]:
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    return [Path(p) / 'share' for p in prefixes] + [Path(sys.prefix) / 'share']


def _msg_text(pkg: str, name: str) -> str:
    for share in _share_dirs():
        f = share / pkg / 'msg' / f'{name}.msg'
        if f.is_file():
            return f.read_text()
    raise RecorderError(f'no definition of {pkg}/msg/{name} under {_share_dirs()}')


def _dependencies(pkg: str, text: str) -> list[tuple[str, str]]:
    """(package, type) of every non-primitive field of a .msg text."""
    deps = []
    for raw in text.splitlines():
        tokens = raw.split('#', 1)[0].split()
        if len(tokens) < 2 or '=' in tokens[1] or (len(tokens) > 2 and tokens[2][0] == '='):
            continue   # blank, comment or constant
        base = re.sub(r'<=\d+$', '', re.sub(r'\[.*\]$', '', tokens[0]))
        if base in PRIMITIVES:
            continue
        if base == 'Header':
            deps.append(('std_msgs', 'Header'))
        elif '/' in base:
            parts = base.split('/')
            deps.append((parts[0], parts[-1]))
        else:
            deps.append((pkg, base))
    return deps


def message_definition(type_name: str) -> str:
    """Full ros2msg definition of e.g. ``sensor_msgs/msg/LaserScan`` with nested types."""
    pkg, _, name = type_name.split('/')
    main = _msg_text(pkg, name)
    seen: dict[str, str] = {}
    stack = _dependencies(pkg, main)
    while stack:
        dpkg, dname = stack.pop(0)
        key = f'{dpkg}/{dname}'
        if key in seen:
            continue
        text = _msg_text(dpkg, dname)
        seen[key] = text
        stack.extend(_dependencies(dpkg, text))
    parts = [main.rstrip('\n')]
    for key, text in seen.items():
        parts += [SEPARATOR, f'MSG: {key}', text.rstrip('\n')]
    return '\n'.join(parts) + '\n'


def type_name_of(msg_class: type) -> str:
    """'pkg/msg/Name' of a generated message class."""
    module = msg_class.__module__.split('.')
    return f'{module[0]}/msg/{msg_class.__name__}'


class McapRecorder:
    """Writes serialized (CDR) ROS 2 messages to an MCAP file; ``close`` finalises it."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = open(self.path, 'wb')
        self._writer = Writer(self._file, compression=CompressionType.ZSTD)
        self._writer.start(profile='ros2', library='subapf_planner')
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sequence = 0
        self.count = 0

    def add_topic(self, topic: str, type_name: str, qos_yaml: str = DEFAULT_QOS) -> None:
        if topic in self._channels:
            return
        if type_name not in self._schemas:
            self._schemas[type_name] = self._writer.register_schema(
                name=type_name, encoding='ros2msg',
                data=message_definition(type_name).encode())
        self._channels[topic] = self._writer.register_channel(
            topic=topic, message_encoding='cdr', schema_id=self._schemas[type_name],
            metadata={'offered_qos_profiles': qos_yaml})

    def write(self, topic: str, data: bytes, log_time_ns: int,
              publish_time_ns: int | None = None) -> None:
        """One serialized message; log_time is the receive time [ns]."""
        self._sequence += 1
        self._writer.add_message(channel_id=self._channels[topic], log_time=log_time_ns,
                                 data=bytes(data), publish_time=publish_time_ns
                                 if publish_time_ns is not None else log_time_ns,
                                 sequence=self._sequence)
        self.count += 1

    def close(self) -> None:
        """Write the index and summary and close the file (idempotent)."""
        if self._file is not None:
            self._writer.finish()
            self._file.close()
            self._file = None
