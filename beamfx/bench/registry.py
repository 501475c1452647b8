"""The benchmark registry: what a case is, the registry itself and the reference files.

Paper modules import :func:`register` from here (not from the package), so that the
package's :func:`beamfx.bench.all_cases`, which imports the paper modules, and the paper
modules do not import each other.
"""

import json
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).parent


def reference(file, case_id=None):
    """A reference file of this package (copies of the project's shared references)."""
    data = json.loads((HERE / file).read_text())
    if case_id is None:
        return data
    items = data.get("problems") or data.get("cases")
    for item in items:
        if item["id"] == case_id:
            return item
    raise KeyError(f"{file}: no case {case_id!r}")


@dataclass(frozen=True)
class Case:
    """A benchmark case.

    ``build(elements, degree)`` returns ``(Model, steps)``; ``measure(values)`` turns the probe
    values at the named points (dict from :func:`beamfx.io.probes.evaluate_points`) into named
    quantities; ``reference`` holds the same names (None where the reference is withheld: the
    finest setting is then the reference, and the report says so). ``error`` is the relative
    error norm used against ``tolerance``.
    """

    id: str
    paper: str
    title: str
    build: object
    measure: object
    reference: dict | None
    tolerance: float
    settings: tuple  # (elements, degree) pairs, coarse to fine
    probes: dict = field(default_factory=lambda: {"tip": "b:end"})
    scale: float | None = None  # error = max |value - ref| / scale (None: relative per value)
    note: str = ""
    extra: dict = field(default_factory=dict)
    #: empty (the default): every scene of the case gets the model the scene builder picks
    #: for a user's scene file (planar, statically condensed:
    #: :func:`beamfx.scene.load.choose_model`), so its times are the times of ``beamfx run``.
    #: An opt-out says here why the case times a model of its own instead (the report prints it)
    own_model: str = ""


REGISTRY: dict[str, Case] = {}
#: case id -> the module that registered it (a process of one setting imports only that one)
REGISTERED_IN: dict[str, str] = {}


def register(case):
    """Add ``case`` to :data:`REGISTRY` (its id must be new); return it."""
    import sys

    if case.id in REGISTRY:
        raise ValueError(f"duplicate benchmark case {case.id}")
    REGISTRY[case.id] = case
    REGISTERED_IN[case.id] = sys._getframe(1).f_globals["__name__"]
    return case
