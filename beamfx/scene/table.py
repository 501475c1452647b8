"""Typed access to a TOML table that reports the file and key path of every mistake.

Every number read is finite and at most :data:`MAX_MAGNITUDE` in size (NaN and infinities are
refused wherever a number is read, and range tests are written ``not value > 0`` so that NaN
could not pass them anyway), every integer lies within :data:`MAX_INT`.
"""

import math
import numbers


class SceneError(ValueError):
    """Bad input in a scene file."""


#: the largest integer any key takes; sizes have their own, smaller bounds ([limits])
MAX_INT = 10**9
#: the largest magnitude of any number: far beyond every physical value in SI units, and small
#: enough that products of a few of them (E·h·w³) stay finite in double precision
MAX_MAGNITUDE = 1e50


def is_number(value):
    """A finite real number (not a bool) of magnitude at most :data:`MAX_MAGNITUDE`."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        return False
    if isinstance(value, int):
        return abs(value) <= MAX_MAGNITUDE  # math.isfinite(10**400) would raise OverflowError
    return math.isfinite(value) and abs(value) <= MAX_MAGNITUDE


def number_problem(value, positive=False):
    """Why ``value`` is not a finite number (> 0 if ``positive``), or None."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        return f"expected a number, got {_short(value)}"
    if not is_number(value):
        why = "a finite number" + (" > 0" if positive else "")
        return f"= {_short(value)}: must be {why} of magnitude at most {MAX_MAGNITUDE:.0e}"
    if positive and not value > 0:
        return f"= {value!r}: must be a finite number > 0"
    return None


_TYPE_NAMES = {
    float: "a number",
    int: "an integer",
    str: "a string",
    bool: "true or false",
    list: "a list",
    dict: "a table",
}


def joined(where, message):
    """``file: key: message``, or ``file: key = value: why`` for a message "= value: why"."""
    return f"{where} {message}" if message.startswith("= ") else f"{where}: {message}"


def _short(value, limit=80):
    """``repr(value)`` cut to ``limit`` characters (a hostile value may be huge); TOML's
    ``true``/``false`` for booleans."""
    text = str(value).lower() if isinstance(value, bool) else repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


class Table:
    """A TOML table being read: ``get`` marks keys as used, ``done`` rejects unknown keys."""

    def __init__(self, data, path, file):
        if not isinstance(data, dict):
            raise SceneError(f"{file}: {path or 'top level'}: expected a table, got {_short(data)}")
        self.data, self.path, self.file, self.used = data, path, file, set()

    def where(self, key):
        """``file: path.key``, how errors name the key."""
        return f"{self.file}: {self.path + '.' if self.path else ''}{key}"

    def fail(self, key, message):
        """Raise a :class:`SceneError` naming ``key`` and its file; if ``key`` is absent and
        the table has an unread key spelled like it, that key is named instead (a missing
        ``stiffness`` beside a ``stiffnes`` is the misspelling's fault)."""
        if key not in self.data:
            import difflib

            unread = [k for k in self.data if k not in self.used and isinstance(k, str)]
            near = difflib.get_close_matches(key, unread, n=1, cutoff=0.75)
            if near:
                raise SceneError(f"{self.where(near[0])}: unknown key; did you mean {key!r}?")
        raise SceneError(joined(self.where(key), message))

    def has(self, key):
        """Whether the table has ``key``."""
        return key in self.data

    def get(self, key, kind=float, default=..., choices=None, positive=False):
        """Value of ``key`` checked against ``kind`` (float, int, str, bool, list, dict, 'vec3')."""
        self.used.add(key)
        if key not in self.data:
            if default is ...:
                self.fail(key, "missing" + (f"; allowed: {list(choices)}" if choices else ""))
            return default
        value = self.data[key]
        if kind == "vec3":
            ok = isinstance(value, list) and len(value) == 3 and all(map(is_number, value))
            if not ok:
                self.fail(key, f"expected a list of 3 finite numbers, got {_short(value)}")
            return tuple(float(v) for v in value)
        if kind is float:
            problem = number_problem(value, positive)
            if problem:
                self.fail(key, problem)
            value = float(value)
        elif kind is int:
            if not isinstance(value, int) or isinstance(value, bool):
                self.fail(key, f"expected an integer, got {_short(value)}")
            if abs(value) > MAX_INT:
                self.fail(key, f"= {value}: must be an integer of at most {MAX_INT:.0e}")
        elif not isinstance(value, kind):
            kinds = kind if isinstance(kind, tuple) else (kind,)
            names = " or ".join(_TYPE_NAMES.get(k, getattr(k, "__name__", str(k))) for k in kinds)
            self.fail(key, f"expected {names}, got {_short(value)}")
        if choices is not None and value not in choices:
            self.fail(key, f"{_short(value)} is not allowed; allowed: {list(choices)}")
        if positive and not value > 0:
            self.fail(key, f"= {value!r}: must be > 0")
        return value

    def numbers(self, key, default=..., count=None, least=0):
        """A list of finite numbers (``count`` of them, or at least ``least``) as floats."""
        value = self.get(key, list, default)
        if value is default and not self.has(key):
            return default
        n = len(value)
        if not all(map(is_number, value)) or (count or n) != n or n < least:
            size = f"{count}" if count else f"at least {least}"
            self.fail(key, f"expected a list of {size} finite numbers, got {_short(value)}")
        return [float(v) for v in value]

    def table(self, key, default=...):
        """Sub-table ``key`` as a :class:`Table` (None if it is missing and ``default`` is None)."""
        value = self.get(key, dict, default)
        return (
            None
            if value is None
            else Table(value, f"{self.path + '.' if self.path else ''}{key}", self.file)
        )

    def tables(self, key):
        """An array of tables (``[[key]]``), each as a Table with an indexed path."""
        items = self.get(key, list, [])
        return [Table(item, f"{key}[{i}]", self.file) for i, item in enumerate(items)]

    def done(self, allowed_note=""):
        """Fail on the first key no getter asked for, listing the allowed keys."""
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            self.fail(
                unknown[0], f"unknown key; allowed keys here: {sorted(self.used)}{allowed_note}"
            )
