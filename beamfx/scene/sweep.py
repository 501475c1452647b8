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
or by the ``name`` of an entry (``beams.bend``).

A member's scene is built when first asked for (:attr:`Member.scene`), so a sweep of 10⁴
members is read in a fraction of a second. When the file is read, the members are bounded
(``[limits] max_members``) and validated: all of them for a small sweep
(:data:`CHECK_ALL` members or fewer), otherwise every value of every table once, with the other
tables at their first values; so a bad value is reported before anything is solved. A bad
combination of good values (elements of one table and degree of another beyond
``max_unknowns``, or modes of one beyond the dofs of another's mesh) in a large sweep is
found by ``beamfx run``, which builds every member before any solve
(:func:`beamfx.runner.check_members`, 2-5 ms a member), and by ``beamfx check`` up to
:data:`beamfx.runner.CHECK_EVERY_MEMBER` members, and refused naming the member.
"""

import copy
import itertools
import math
import os
import re
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

from .files import read_toml
from .limits import Limits
from .load import Scene, parse_scene
from .schema import read_settings
from .table import SceneError, Table

CHECK_ALL = 64  # a sweep of at most this many members has every member validated on reading


@dataclass(frozen=True)
class Member:
    """One scene of a sweep: its number, the values set (key path -> value) and the scene
    (:class:`~beamfx.scene.Scene`, built on first use)."""

    index: int
    values: dict
    build: object = field(repr=False, compare=False)  # () -> Scene

    @cached_property
    def scene(self):
        """The member's :class:`~beamfx.scene.Scene` (a SceneError if its values clash)."""
        return self.build()


@dataclass(frozen=True)
class Sweep:
    """The members of a sweep file and the folder their results go into (one subfolder each)."""

    file: str
    keys: tuple
    members: tuple
    output_dir: str

    @property
    def validated(self):
        """The scenes of the members built so far (those validated on reading)."""
        return tuple(m.scene for m in self.members if "scene" in m.__dict__)


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


def _member(data, values, file, base, index):
    """() -> the Scene of the member of ``data`` with ``values`` set."""

    def build():
        member = copy.deepcopy(data)
        for key, value in values.items():
            node, tok = _parent(member, key, f"{file}: sweep: {key}")
            node[tok] = value
        label = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        return parse_scene(member, f"{file} (sweep member {index}: {label})", base)

    return build


def _to_check(sizes):
    """Indices of the members validated on reading: all of a small sweep; else the first
    member and, for each table, the members that differ from it in that table only."""
    n = math.prod(sizes)
    if n <= CHECK_ALL:
        return range(n)
    strides = [math.prod(sizes[a + 1 :]) for a in range(len(sizes))]  # itertools.product order
    return sorted({0} | {j * strides[a] for a, size in enumerate(sizes) for j in range(1, size)})


def parse_sweep(data: dict, file: str = "<scene>", base: Path = Path(".")) -> Sweep:
    """The :class:`Sweep` of already-parsed TOML data with ``[[sweep]]`` tables."""
    data = dict(data)
    entries = data.pop("sweep")
    top = Table({"sweep": [entries] if isinstance(entries, dict) else entries}, "", file)
    axes = _axes(top.tables("sweep"), file)
    keys = tuple(k for ks, _ in axes for k in ks)
    if len(set(keys)) < len(keys):
        top.fail("sweep", f"a key is swept twice: {list(keys)}")
    sizes = [len(vals) for _, vals in axes]
    limits = read_settings(Limits, Table(data, "", file).table("limits", {}))
    if math.prod(sizes) > limits.max_members:
        top.fail(
            "sweep",
            f"{' x '.join(map(str, sizes))} = {math.prod(sizes)} members; allowed: at most "
            f"{limits.max_members} ([limits] max_members raises it)",
        )
    members = []
    for index, combo in enumerate(itertools.product(*(vals for _, vals in axes))):
        values = dict(zip(keys, (v for vs in combo for v in vs)))
        members.append(Member(index, values, _member(data, values, file, base, index)))
    for index in _to_check(sizes):
        members[index].scene  # noqa: B018  (validates; the scene is kept for the run)
    return Sweep(file, keys, tuple(members), members[0].scene.output_dir)


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
