"""Configurations as plain data: frozen dataclasses to and from JSON-ready dicts.

Every configuration in pianobot is a frozen dataclass (``KeyboardSpec``, ``WorldConfig``,
``EnvConfig``, ``SACConfig``, ``TrainConfig``, ...) whose defaults are the single source of
truth: the command line reads its defaults from them. A stored model records its configuration
with :func:`to_dict`; :func:`from_dict` rebuilds it, typed from the dataclass's annotations
(nested dataclasses, tuples, optional values), and says which field is wrong when a value does
not fit.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from typing import Any, TypeVar

from pianobot.errors import quote

T = TypeVar("T")


class ConfigError(ValueError):
    """A value does not fit its field; the message starts with the field's dotted path."""


def check_ranges(config: Any, **ranges: tuple[float, float]) -> None:
    """Raise ValueError naming the first field of ``config`` outside its (low, high) range
    (inclusive): the physical and numerical settings' sanity checks in ``__post_init__``."""
    for name, (low, high) in ranges.items():
        value = getattr(config, name)
        if not low <= value <= high:
            raise ValueError(f"{name} {value} must lie between {low:g} and {high:g}")


def to_dict(config: Any) -> dict:
    """A configuration as nested dicts, lists and plain values (JSON-ready)."""
    return dataclasses.asdict(config)


def from_dict(cls: type[T], data: Any, path: str = "config") -> T:
    """Rebuild a ``cls`` from :func:`to_dict`'s output (or its JSON round trip).

    Fields left out take their defaults; unknown fields, values of the wrong type and
    non-finite numbers raise :class:`ConfigError` naming the field, as do the dataclass's own
    checks (``__post_init__``)."""
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping of fields, got {_show(data)}")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ConfigError(f"{path}.{quote(unknown[0])}: not a field of {cls.__name__}")
    hints = typing.get_type_hints(cls)
    values = {name: _convert(hints[name], value, f"{path}.{name}") for name, value in data.items()}
    try:
        return cls(**values)
    except (TypeError, ValueError) as e:
        raise ConfigError(f"{path}: {quote(str(e), 200)}") from None


def _convert(kind: Any, value: Any, path: str) -> Any:
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        options = [a for a in args if a is not type(None)]
        for option in options[:-1]:
            try:
                return _convert(option, value, path)
            except ConfigError:
                pass
        return _convert(options[-1], value, path)
    if dataclasses.is_dataclass(kind):
        return from_dict(kind, value, path)
    if origin is tuple:
        if not isinstance(value, (list, tuple)):
            raise ConfigError(f"{path}: expected a list, got {_show(value)}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(args[0], v, f"{path}[{i}]") for i, v in enumerate(value))
        if len(args) != len(value):
            raise ConfigError(f"{path}: expected {len(args)} values, got {len(value)}")
        return tuple(_convert(a, v, f"{path}[{i}]") for i, (a, v) in enumerate(zip(args, value)))
    if origin is typing.Literal:
        if value not in args:
            raise ConfigError(f"{path}: expected one of {', '.join(map(repr, args))}, got {_show(value)}")
        return value
    if kind is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{path}: expected true or false, got {_show(value)}")
        return value
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{path}: expected a whole number, got {_show(value)}")
        return value
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ConfigError(f"{path}: expected a finite number, got {_show(value)}")
        return float(value)
    if kind is str:
        if not isinstance(value, str):
            raise ConfigError(f"{path}: expected a string, got {_show(value)}")
        return value
    raise ConfigError(f"{path}: fields of type {kind} cannot be read")  # a new field type: teach _convert


def _show(value: Any) -> str:
    return f"{type(value).__name__} {quote(repr(value), 40)}"
