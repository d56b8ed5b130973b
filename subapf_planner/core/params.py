"""Validated, frozen parameter dataclasses: one metadata source for every parameter.

Each field is declared with :func:`param`: default, description, unit, range
or choices, and whether it may change at run time. ``PlannerConfig``,
``Supervision``, ``SimConfig``, ``ScanFaults`` and the nodes' own options are
built this way; the ROS nodes declare their parameters (with descriptors) from
the same metadata, and ``config/planner.yaml`` documents the same names
(``test/test_config.py`` keeps them equal).
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from typing import Any, Mapping, TypeVar

T = TypeVar('T')


class ConfigError(ValueError):
    """A parameter value is missing, unknown, of the wrong type or out of range."""


def param(default: Any, description: str, unit: str = '', lo: float | None = None,
          hi: float | None = None, choices: tuple[str, ...] | None = None,
          read_only: bool = False) -> Any:
    """A dataclass field carrying its documentation and admissible values.

    ``read_only``: read at start only (a change at run time is refused).
    """
    meta = {'description': description, 'unit': unit, 'lo': lo, 'hi': hi,
            'choices': choices, 'read_only': read_only}
    return dataclasses.field(default=default, metadata=meta)


def kind_of(f: dataclasses.Field) -> type:
    """bool, int, float, str or tuple (of strings): the declared type of a field."""
    return {'bool': bool, 'int': int, 'float': float, 'str': str,
            'tuple[str, ...]': tuple}.get(f.type, f.type)


def describe(f: dataclasses.Field) -> str:
    """One sentence about a field: description [unit], choices or range, read-only (the
    comment of config/planner.yaml, the nodes' --help)."""
    m = f.metadata
    text = m['description'] + (f' [{m["unit"]}]' if m['unit'] else '')
    if m.get('choices'):
        text += '; one of: ' + ', '.join(m['choices'])
    elif m.get('lo') is not None:
        text += f'; range [{m["lo"]}, {m["hi"]}]'
    if m.get('read_only'):
        text += '; read-only'
    return text + '.'


def closest_name(name: str, names: Any) -> str | None:
    """The name among ``names`` closest to ``name`` (a misspelling), or None."""
    close = difflib.get_close_matches(name, sorted(names), n=1, cutoff=0.75)
    return close[0] if close else None


def check_field(f: dataclasses.Field, value: Any) -> None:
    """Raise ConfigError naming the field when ``value`` is not admissible."""
    meta, name, kind = f.metadata, f.name, kind_of(f)
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f'{name}: expected a number, got {value!r}')
        if not math.isfinite(value):
            raise ConfigError(f'{name}: must be finite, got {value!r}')
    elif kind is int and (isinstance(value, bool) or not isinstance(value, int)):
        raise ConfigError(f'{name}: expected an integer, got {value!r}')
    elif kind is bool and not isinstance(value, bool):
        raise ConfigError(f'{name}: expected true or false, got {value!r}')
    elif kind is str and not isinstance(value, str):
        raise ConfigError(f'{name}: expected a string, got {value!r}')
    elif kind is tuple and not (isinstance(value, tuple)
                                and all(isinstance(v, str) for v in value)):
        raise ConfigError(f'{name}: expected a list of strings, got {value!r}')
    if meta.get('choices') is not None and value not in meta['choices']:
        raise ConfigError(f'{name}: {value!r} is not one of {", ".join(meta["choices"])}')
    lo, hi = meta.get('lo'), meta.get('hi')
    if lo is not None and not lo <= value <= hi:
        raise ConfigError(f'{name}: {value!r} is outside [{lo}, {hi}] {meta["unit"]}'.rstrip())


def check_fields(obj: Any) -> None:
    """Validate every field of a param dataclass instance (call in __post_init__)."""
    for f in dataclasses.fields(obj):
        check_field(f, getattr(obj, f.name))


def build(cls: type[T], values: Mapping[str, Any], *, ignore_unknown: bool = False) -> T:
    """An instance of ``cls`` from a mapping (ints accepted for floats); unknown keys
    are an error unless ignored; missing keys take their defaults."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(values) - set(fields))
    if unknown and not ignore_unknown:
        raise ConfigError(f'unknown parameter(s): {", ".join(unknown)}')
    kwargs = {}
    for name, f in fields.items():
        if name in values:
            v = values[name]
            if kind_of(f) is float and isinstance(v, int) and not isinstance(v, bool):
                v = float(v)
            elif kind_of(f) is tuple and isinstance(v, list):
                v = tuple(v)
            kwargs[name] = v
    return cls(**kwargs)

