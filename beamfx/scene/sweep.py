"""``[[sweep]]``: one scene file that describes a family of scenes (a parameter sweep).

Each ``[[sweep]]`` table names one or more keys of the same file and the values they take::

    [[sweep]]
    key = "loads[0].force"               # a key path as in the error messages
    values = [[0, 0, 150], [0, 0, 300], [0, 0, 600]]

    [[sweep]]
    key = ["beams.bend.elements", "beams.bend.degree"]   # changed together
    values = [[4, 2], [2, 4]]

The members are all combinations of the tables' values (here 3 x 2 = 6 scenes). A key path
goes through tables by name, through arrays of tables by index (``loads[0]`` or ``loads.0``)
or by the ``name`` of an entry (``beams.bend``). Every member is validated when the file is
read, so a bad value is reported before anything is solved.
"""

import copy
import itertools
import os
import re
from dataclasses import dataclass
from pathlib import Path

from .load import Scene, parse_scene, read_toml
from .table import SceneError, Table


@dataclass(frozen=True)
class Member:
    """One scene of a sweep: its number, the values set (key path -> value) and the scene."""

    index: int
    values: dict
    scene: Scene


@dataclass(frozen=True)
class Sweep:
    """The members of a sweep file and the folder their results go into (one subfolder each)."""

    file: str
    keys: tuple
    members: tuple
    output_dir: str


def _tokens(key):
    return re.findall(r"[^.\[\]]+", key)


def _parent(data, key, where):
    """The table or array holding the last token of ``key``, and that token (index or name)."""
    node, path = data, []
    tokens = _tokens(key)
    if not tokens:
        raise SceneError(f"{where}: empty key path")  # e.g. "" or "."
    for i, tok in enumerate(tokens):
        last = i == len(tokens) - 1
        if isinstance(node, list):
            names = [e.get("name") for e in node if isinstance(e, dict) and "name" in e]
            if tok.isdigit() and int(tok) < len(node):
                tok = int(tok)
            elif tok in names:
                tok = names.index(tok)
            else:
                raise SceneError(
                    f"{where}: {'.'.join(path) or 'top level'} has no entry {tok!r}; "
                    f"allowed: an index 0..{len(node) - 1}"
                    + (f" or a name {names}" if names else "")
                )
        elif isinstance(node, dict):
            if tok not in node and not last:
                raise SceneError(
                    f"{where}: {'.'.join(path) or 'top level'} has no key {tok!r}; "
                    f"present: {sorted(node)}"
                )
        else:
            raise SceneError(f"{where}: {'.'.join(path)} is a value, not a table")
        if last:
            return node, tok
        node = node[tok]
        path.append(str(tok))


def _axes(entries, file):
    """[(keys, [value tuples])] of the ``[[sweep]]`` tables, each checked for its own shape."""
    axes = []
    for t in entries:
        key = t.data.get("key")
        keys = [key] if isinstance(key, str) else key
        if not isinstance(keys, list) or not keys or not all(isinstance(k, str) for k in keys):
            t.fail("key", f"expected a key path or a list of them, got {key!r}")
        values = t.get("values", list)
        if not values:
            t.fail("values", "empty: give at least one value")
        if len(keys) > 1 and not all(isinstance(v, list) and len(v) == len(keys) for v in values):
            t.fail("values", f"each value must be a list of {len(keys)} (one per key in {keys})")
        t.used.add("key")
        t.done()
        axes.append((keys, [v if len(keys) > 1 else [v] for v in values]))
    return axes


def parse_sweep(data: dict, file: str = "<scene>", base: Path = Path(".")) -> Sweep:
    """The :class:`Sweep` of already-parsed TOML data with ``[[sweep]]`` tables."""
    data = dict(data)
    entries = data.pop("sweep")
    top = Table({"sweep": [entries] if isinstance(entries, dict) else entries}, "", file)
    axes = _axes(top.tables("sweep"), file)
    keys = tuple(k for ks, _ in axes for k in ks)
    if len(set(keys)) < len(keys):
        top.fail("sweep", f"a key is swept twice: {list(keys)}")
    members = []
    for index, combo in enumerate(itertools.product(*(vals for _, vals in axes))):
        values = dict(zip(keys, (v for vs in combo for v in vs)))
        member = copy.deepcopy(data)
        for key, value in values.items():
            node, tok = _parent(member, key, f"{file}: sweep: {key}")
            node[tok] = value
        label = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        scene = parse_scene(member, f"{file} (sweep member {index}: {label})", base)
        members.append(Member(index, values, scene))
    out = members[0].scene.output_dir if members else "results"
    return Sweep(file, keys, tuple(members), out)


def load_sweep(path: str | os.PathLike) -> Sweep | None:
    """The :class:`Sweep` of the file at ``path``, or None if it has no ``[[sweep]]`` table."""
    loaded = load_scene_or_sweep(path)
    return loaded if isinstance(loaded, Sweep) else None


def load_scene_or_sweep(path: str | os.PathLike) -> Scene | Sweep:
    """The file at ``path`` read once: a :class:`Sweep` if it has ``[[sweep]]`` tables, else
    its :class:`Scene`."""
    path = Path(path)
    data = read_toml(path)
    parse = parse_sweep if "sweep" in data else parse_scene
    return parse(data, str(path), path.parent)
