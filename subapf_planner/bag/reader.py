"""Reading rosbag2-style MCAP files into typed ROS 2 messages, with clear errors."""

from __future__ import annotations

from dataclasses import dataclass
import importlib
from pathlib import Path
from typing import Any, Iterator

from mcap.exceptions import McapError
from mcap.reader import make_reader
from rclpy.serialization import deserialize_message


class BagError(ValueError):
    """The file is missing, not MCAP, truncated, or lacks what the caller needs."""


@dataclass(frozen=True)
class BagMessage:
    topic: str
    type_name: str
    log_time_ns: int
    message: Any


def message_class(type_name: str) -> type:
    """The generated class of 'pkg/msg/Name'."""
    try:
        pkg, kind, name = type_name.split('/')
        return getattr(importlib.import_module(f'{pkg}.{kind}'), name)
    except (ValueError, ImportError, AttributeError) as exc:
        raise BagError(f'unknown message type {type_name!r}') from exc


def _open(path: str | Path):
    path = Path(path)
    try:
        return path.open('rb')
    except OSError as exc:
        raise BagError(f'{path}: cannot open: {exc.strerror or exc}') from exc


def topics(path: str | Path) -> dict[str, str]:
    """topic -> type name, from the file's summary (or by reading it if it has none)."""
    with _open(path) as f:
        try:
            summary = make_reader(f).get_summary()
        except (McapError, ValueError, EOFError, OSError) as exc:
            raise BagError(f'{path}: not a readable MCAP file, or truncated ({exc})') from exc
    if summary is None:
        return {m.topic: m.type_name for m in read(path, decode=False)}
    return {c.topic: summary.schemas[c.schema_id].name if c.schema_id in summary.schemas
            else '' for c in summary.channels.values()}


def read(path: str | Path, wanted: set[str] | None = None,
         decode: bool = True) -> Iterator[BagMessage]:
    """Messages in log-time order; ``wanted`` limits the topics.

    Raises BagError for a missing or non-MCAP file, a truncated one (after the
    messages that could be read), and a channel that is not CDR-encoded ROS 2.
    """
    with _open(path) as f:
        reader = make_reader(f)
        classes: dict[int, type] = {}
        try:
            for schema, channel, message in reader.iter_messages(
                    topics=list(wanted) if wanted else None, log_time_order=True):
                if channel.message_encoding != 'cdr' or schema is None \
                        or schema.encoding != 'ros2msg':
                    raise BagError(f'{path}: topic {channel.topic} is not a ROS 2 CDR channel '
                                   f'(encoding {channel.message_encoding!r})')
                msg: Any = None
                if decode:
                    cls = classes.get(channel.id)
                    if cls is None:
                        cls = classes[channel.id] = message_class(schema.name)
                    try:
                        msg = deserialize_message(message.data, cls)
                    except Exception as exc:   # rclpy raises plain exceptions for bad CDR
                        raise BagError(f'{path}: message on {channel.topic} does not '
                                       f'decode as {schema.name}: {exc}') from exc
                yield BagMessage(channel.topic, schema.name, message.log_time, msg)
        except BagError:
            raise
        except (McapError, ValueError, EOFError, OSError, KeyError, AssertionError) as exc:
            raise BagError(f'{path}: not a readable MCAP file or truncated ({exc!r})') from exc
