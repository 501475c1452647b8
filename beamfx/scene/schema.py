"""Read a settings dataclass (:mod:`beamfx.settings`) from a scene table, key by key.

Every field is read by its name with its type, range and choices checked; NaN and infinite
numbers are refused; a settings class may add checks across fields with a method
``problems(self)`` yielding ``(key, message)`` pairs, reported with the file and key path.
"""

import dataclasses
import math
import numbers

from ..settings import Vec3, describe, is_settings, specs
from .table import SceneError


def _number(value):
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _convert(spec, value, fail):
    """``value`` as the field's type, or ``fail`` with the allowed values."""
    kind = spec.kind
    bad = f"expected {describe(spec)}, got {value!r}"
    if kind is object:
        return spec.parse(value, fail)
    if kind is bool:
        if not isinstance(value, bool):
            fail(bad)
        return value
    if kind is str:
        if not isinstance(value, str):
            fail(bad)
        return value
    if kind is int:
        if not isinstance(value, int) or isinstance(value, bool):
            fail(bad)
        return value
    if kind is float:
        if not _number(value) or not math.isfinite(value):
            fail(bad)
        return float(value)
    if kind == tuple[str, ...]:
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            fail(bad)
        return tuple(value)
    ok = isinstance(value, list) and all(_number(v) and math.isfinite(v) for v in value)
    if not ok or (kind == Vec3 and len(value) != 3) or not value:
        fail(bad)
    return tuple(float(v) for v in value)


def _check_range(spec, value, fail):
    values = value if isinstance(value, tuple) else (value,)
    for v in values:
        if spec.choices is not None and v not in spec.choices:
            fail(f"{v!r} is not allowed; allowed: {list(spec.choices)}")
        if isinstance(v, (str, bool)):
            continue
        if (
            (spec.positive and v <= 0)
            or (spec.low is not None and v < spec.low)
            or (spec.high is not None and v > spec.high)
        ):
            fail(f"must be {describe(spec)}, got {v!r}")


def read_settings(cls: type, table, defaults: dict | None = None, done: bool = True):
    """An instance of the settings class ``cls`` from ``table`` (:class:`~.table.Table`).

    Args:
        cls: a frozen dataclass with :func:`~beamfx.settings.option` fields.
        table: the scene table; None reads an empty one (all defaults).
        defaults: computed defaults by field name, used when the key is left out (e.g. a
            default that depends on another key).
        done: reject keys of ``table`` that are not fields (set False when the caller reads
            more keys from the same table).

    Raises:
        SceneError: naming the file, the key path and the allowed values.
    """
    defaults = defaults or {}
    values = {}
    for spec in specs(cls):
        where = table.where(spec.name) if table is not None else spec.name

        def fail(message, where=where):
            raise SceneError(f"{where}: {message}")

        present = table is not None and table.has(spec.name)
        if is_settings(spec.kind):  # a sub-table, all defaults when left out
            sub = table.table(spec.name, {}) if table is not None else None
            values[spec.name] = read_settings(spec.kind, sub)
            continue
        if table is not None:
            table.used.add(spec.name)
        if not present:
            if spec.name in defaults:
                values[spec.name] = defaults[spec.name]
            elif spec.default is dataclasses.MISSING:
                fail(f"missing; expected {describe(spec)}")
            continue
        value = _convert(spec, table.data[spec.name], fail)
        _check_range(spec, value, fail)
        values[spec.name] = value
    obj = cls(**values)
    for key, message in getattr(obj, "problems", lambda: ())():
        where = table.where(key) if table is not None else key
        raise SceneError(f"{where}: {message}")
    if done and table is not None:
        table.done()
    return obj


__all__ = ["read_settings"]
