"""Typed settings whose fields are the scene keys: one declaration for the parser and the docs.

A settings class is a frozen dataclass whose fields are declared with :func:`option`. The
scene reader (:func:`beamfx.scene.schema.read_settings`) reads each field from its TOML table
by the field's name, checks its type (from the annotation), range and choices, and rejects
unknown keys; :func:`markdown_table` prints the same fields as the table of docs/scenes.md, so
the schema and the docs cannot drift apart.

Annotations understood: ``float``, ``int``, ``str``, ``bool``, ``Vec3`` (3 numbers),
``tuple[float, ...]`` (a list of numbers), ``tuple[str, ...]`` (a list of strings), each
optionally ``| None`` (the key may be left out; its default is then None); another settings
class (a sub-table, e.g. ``[analysis.damping]``); ``object`` with a ``parse`` function.

This module is pure Python (no NumPy, no DOLFINx), so every layer may import it.
"""

import dataclasses
import types
import typing

Vec3 = tuple[float, float, float]

_TYPE_WORDS = {
    float: "number",
    int: "integer",
    str: "string",
    bool: "true/false",
    Vec3: "3 numbers",
    tuple[float, ...]: "list of numbers",
    tuple[str, ...]: "list of strings",
}


def option(
    default=dataclasses.MISSING,
    doc="",
    choices=None,
    positive=False,
    low=None,
    high=None,
    parse=None,
    word=None,
):
    """A settings field: its default, one line of documentation and its allowed values.

    Args:
        default: the value when the key is left out (``dataclasses.MISSING``: required).
        doc: what the key means, with its unit (goes into the docs' table).
        choices: the allowed values (strings or numbers).
        positive: the value (each value of a list) must be > 0.
        low: inclusive lower bound of the value.
        high: inclusive upper bound of the value.
        parse: for a value no annotation describes (e.g. ``[component, value]``): a function
            ``(value, fail) -> value`` that converts it or calls ``fail(message)``; the
            annotation is then ``object`` and ``word`` says in words what is allowed.
        word: what a ``parse``d value may be, in words (for errors and the docs' table).
    """
    meta = {"doc": doc, "choices": choices, "positive": positive, "low": low, "high": high}
    meta.update(parse=parse, word=word)
    if isinstance(default, list | dict | set):
        raise TypeError("use a tuple (immutable) as the default of a list-valued option")
    return dataclasses.field(default=default, metadata=meta)


class Spec(typing.NamedTuple):
    """What the reader needs to know of one field."""

    name: str
    kind: object  # float, int, str, bool, Vec3, tuple[float, ...] or tuple[str, ...]
    optional: bool  # None is allowed
    default: object  # dataclasses.MISSING when required
    doc: str
    choices: tuple | None
    positive: bool
    low: float | None
    high: float | None
    parse: object = None  # (value, fail) -> value, for kind ``object``
    word: str | None = None  # the allowed values in words, for kind ``object``


def is_settings(kind):
    """A nested settings class (a sub-table of the scene)?"""
    return isinstance(kind, type) and dataclasses.is_dataclass(kind)


def specs(cls):
    """The :class:`Spec` of every field of the settings class ``cls``, in declaration order."""
    hints = typing.get_type_hints(cls)
    out = []
    for f in dataclasses.fields(cls):
        kind, optional = hints[f.name], False
        args = typing.get_args(kind)
        if isinstance(kind, types.UnionType) or typing.get_origin(kind) is typing.Union:
            rest = [a for a in args if a is not type(None)]
            kind, optional = rest[0], len(rest) < len(args)
        if kind not in _TYPE_WORDS and kind is not object and not is_settings(kind):
            raise TypeError(f"{cls.__name__}.{f.name}: unsupported settings type {kind!r}")
        m = f.metadata
        out.append(
            Spec(
                f.name,
                kind,
                optional,
                f.default,
                m.get("doc", ""),
                tuple(m["choices"]) if m.get("choices") is not None else None,
                m.get("positive", False),
                m.get("low"),
                m.get("high"),
                m.get("parse"),
                m.get("word"),
            )
        )
    return out


def describe(spec):
    """The allowed values of a field in words (for errors and docs)."""
    if spec.kind is object:
        return spec.word or "see the docs"
    if is_settings(spec.kind):
        return "a table: " + ", ".join(f"`{s.name}`" for s in specs(spec.kind))
    word = _TYPE_WORDS[spec.kind]
    if spec.choices is not None:
        listed = ", ".join(repr(c) for c in spec.choices)
        return f"a list of {listed}" if spec.kind == tuple[str, ...] else f"one of {listed}"
    parts = [word]
    if spec.positive:
        parts.append("> 0")
    if spec.low is not None and spec.high is not None:
        parts.append(f"in [{spec.low:g}, {spec.high:g}]")
    elif spec.low is not None:
        parts.append(f">= {spec.low:g}")
    elif spec.high is not None:
        parts.append(f"<= {spec.high:g}")
    return " ".join(parts)


def markdown_table(cls, defaults=None):
    """The docs' table of a settings class: key, allowed values, default, meaning.

    ``defaults`` overrides the printed default of fields whose default is computed (e.g.
    ``{"output_every": "about 100 frames per run"}``).
    """
    defaults = defaults or {}
    rows = ["| key | allowed | default | meaning |", "|---|---|---|---|"]
    for s in specs(cls):
        if s.name in defaults:
            d = defaults[s.name]
        elif s.default is dataclasses.MISSING:
            d = "required"
        else:
            d = "none" if s.default is None else repr(s.default)
        rows.append(f"| `{s.name}` | {describe(s)} | {d} | {s.doc} |")
    return "\n".join(rows) + "\n"


__all__ = ["Spec", "Vec3", "describe", "is_settings", "markdown_table", "option", "specs"]
