"""Read a settings dataclass (:mod:`beamfx.settings`) from a scene table, key by key.

Every field is read by its name with its type, range and choices checked; NaN and infinite
numbers are refused; a settings class may add checks across fields with a method
``problems(self)`` yielding ``(key, message)`` pairs, reported with the file and key path.
"""

import dataclasses
import numbers

from ..settings import Vec3, describe, is_settings, specs
from .table import MAX_INT, SceneError, is_number, joined


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
        if abs(value) > MAX_INT:
            fail(f"= {value}: must be at most {MAX_INT:.0e}")
        return value
    if kind is float:
        if not is_number(value):
            fail(f"= {value!r}: must be a finite {describe(spec)}" if _number(value) else bad)
        return float(value)
    if kind == tuple[str, ...]:
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            fail(bad)
        return tuple(value)
    ok = isinstance(value, list) and all(map(is_number, value))
    if not ok or (kind == Vec3 and len(value) != 3) or not value:
        fail(bad)
    return tuple(float(v) for v in value)


def _check_range(spec, value, fail, max_count=None):
    values = value if isinstance(value, tuple) else (value,)
    if max_count is not None and len(values) > max_count:  # e.g. a list of spin speeds
        fail(f"a list of {len(values)}; allowed: at most {max_count} ([limits] max_count)")
    for v in values:
        if spec.choices is not None and v not in spec.choices:
            fail(f"{v!r} is not allowed; allowed: {list(spec.choices)}")
        if isinstance(v, (str, bool)):
            continue
        if (
            (spec.positive and not v > 0)
            or (spec.low is not None and not v >= spec.low)
            or (spec.high is not None and not v <= spec.high)
        ):
            fail(f"= {v!r}: must be {describe(spec)}")
        if spec.kind is int and max_count is not None and v > max_count:
            fail(f"= {v}: allowed: at most {max_count} ([limits] max_count raises it)")


def read_settings(
    cls: type, table, defaults: dict | None = None, done: bool = True, max_count=None
):
    """An instance of the settings class ``cls`` from ``table`` (:class:`~.table.Table`).

    Args:
        cls: a frozen dataclass with :func:`~beamfx.settings.option` fields.
        table: the scene table; None reads an empty one (all defaults).
        defaults: computed defaults by field name, used when the key is left out (e.g. a
            default that depends on another key).
        done: reject keys of ``table`` that are not fields (set False when the caller reads
            more keys from the same table).
        max_count: the largest value of an integer field (a count of steps, modes, frames:
            ``[limits] max_count``); None: no bound beyond the field's own.

    Raises:
        SceneError: naming the file, the key path and the allowed values.
    """
    defaults = defaults or {}
    values = {}
    for spec in specs(cls):
        where = table.where(spec.name) if table is not None else spec.name

        def fail(message, where=where):
            raise SceneError(joined(where, message))

        present = table is not None and table.has(spec.name)
        if is_settings(spec.kind):  # a sub-table, all defaults when left out
            sub = table.table(spec.name, {}) if table is not None else None
            values[spec.name] = read_settings(spec.kind, sub, max_count=max_count)
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
        _check_range(spec, value, fail, max_count)
        values[spec.name] = value
    obj = cls(**values)
    given = {s.name for s in specs(cls) if table is not None and table.has(s.name)}
    for key, message in (
        *getattr(obj, "problems", lambda: ())(),
        *getattr(obj, "problems_given", lambda given: ())(given),
    ):
        where = table.where(key) if table is not None else key
        raise SceneError(f"{where}: {message}")
    if done and table is not None:
        table.done()
    return obj


__all__ = ["read_settings"]
