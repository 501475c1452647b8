"""Typed access to a TOML table that reports the file and key path of every mistake."""

import numbers


class SceneError(ValueError):
    """Bad input in a scene file."""


_TYPE_NAMES = {
    float: "a number",
    int: "an integer",
    str: "a string",
    bool: "true or false",
    list: "a list",
    dict: "a table",
}


class Table:
    """A TOML table being read: ``get`` marks keys as used, ``done`` rejects unknown keys."""

    def __init__(self, data, path, file):
        if not isinstance(data, dict):
            raise SceneError(f"{file}: {path or 'top level'}: expected a table, got {data!r}")
        self.data, self.path, self.file, self.used = data, path, file, set()

    def where(self, key):
        """``file: path.key``, how errors name the key."""
        return f"{self.file}: {self.path + '.' if self.path else ''}{key}"

    def fail(self, key, message):
        """Raise a :class:`SceneError` naming ``key`` and its file."""
        raise SceneError(f"{self.where(key)}: {message}")

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
            ok = (
                isinstance(value, list)
                and len(value) == 3
                and all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in value)
            )
            if not ok:
                self.fail(key, f"expected a list of 3 numbers, got {value!r}")
            return tuple(float(v) for v in value)
        if kind is float:
            if not isinstance(value, numbers.Real) or isinstance(value, bool):
                self.fail(key, f"expected a number, got {value!r}")
            value = float(value)
        elif kind is int:
            if not isinstance(value, int) or isinstance(value, bool):
                self.fail(key, f"expected an integer, got {value!r}")
        elif not isinstance(value, kind):
            self.fail(key, f"expected {_TYPE_NAMES.get(kind, kind)}, got {value!r}")
        if choices is not None and value not in choices:
            self.fail(key, f"{value!r} is not allowed; allowed: {list(choices)}")
        if positive and value <= 0:
            self.fail(key, f"must be positive, got {value!r}")
        return value

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
