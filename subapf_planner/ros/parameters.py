"""ROS parameters from the package's parameter dataclasses (core/params.py).

Each node declares every field of its dataclasses with the field's default and
a ParameterDescriptor (description with unit, range or choices, read-only),
reads them back into validated dataclasses, and validates a run-time change by
building the dataclasses with it: the descriptors, the YAML and the validation
all come from one metadata source. A value given for a name the node does not
declare (a params file, ``-p``, the constructor's overrides) is reported with the
closest declared name (``undeclared``), not dropped in silence.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.node import Node

from ..core.params import build, closest_name, kind_of

T = TypeVar('T')


def descriptor(f: dataclasses.Field) -> ParameterDescriptor:
    """The descriptor of one field: text [unit], range or choices, read-only."""
    m = f.metadata
    d = ParameterDescriptor(description=m['description'] + (f' [{m["unit"]}]' if m['unit']
                                                              else ''),
                            read_only=bool(m.get('read_only')))
    lo, hi = m.get('lo'), m.get('hi')
    if lo is not None and kind_of(f) is int:
        d.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi), step=1)]
    elif lo is not None:
        d.floating_point_range = [FloatingPointRange(from_value=float(lo), to_value=float(hi),
                                                     step=0.0)]
    if m.get('choices'):
        d.additional_constraints = 'one of: ' + ', '.join(m['choices'])
    return d


def declare(node: Node, *classes: type) -> None:
    """Declare every field of ``classes`` on ``node`` with its default and descriptor."""
    for cls in classes:
        for f in dataclasses.fields(cls):
            node.declare_parameter(f.name, f.default, descriptor(f))


def read(node: Node, cls: type[T], changes: dict[str, Any] | None = None) -> T:
    """The node's current values of ``cls``'s fields, with ``changes`` on top, validated
    (ConfigError naming the parameter when a value is not admissible)."""
    values = {f.name: node.get_parameter(f.name).value for f in dataclasses.fields(cls)}
    values.update({k: v for k, v in (changes or {}).items() if k in values})
    return build(cls, values)


def undeclared(node: Node) -> list[str]:
    """One line for each parameter value given to ``node`` (params files, ``-p``, the
    constructor's parameter_overrides) under a name it has not declared: rclpy ignores
    those; the line names the closest declared one. Call it once every parameter is
    declared."""
    known = set(node._parameters)
    out = []
    for name in sorted(set(node._parameter_overrides) - known):
        close = closest_name(name, known)
        hint = f'; did you mean {close!r}?' if close else '; see --help'
        out.append(f'{name!r} is not a parameter of {node.get_name()}: its value is '
                   f'ignored{hint}')
    return out


def warn_undeclared(node: Node) -> list[str]:
    """Log ``undeclared(node)`` as warnings; returns them."""
    lines = undeclared(node)
    for line in lines:
        node.get_logger().warn(line)
    return lines
