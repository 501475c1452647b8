"""The architecture rules of docs/STYLE (scripts/check_architecture.py) as tests.

Each check compares what it finds with ``KNOWN``, the exact list of today's offenders. A check
with offenders is an expected failure (strict xfail): it fails loudly, with a different error,
when the list changes either way. When an offender is fixed, remove it from ``KNOWN``; when the
list is empty, remove the mark (``_param`` does that). A new offender is never added silently:
fix it instead.
"""

import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "check_architecture.py"
_spec = importlib.util.spec_from_file_location("check_architecture", SCRIPT)
arch = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(arch)

#: today's offenders, exactly (the modules of each import cycle; file::function over 80 lines)
KNOWN = {
    "import_cycles": [],
    "long_functions": [],
}


def _import_cycles():
    return arch.cycles(arch.import_graph())


def _long_functions():
    return sorted(f.id for f in arch.long_functions())


CHECKS = {"import_cycles": _import_cycles, "long_functions": _long_functions}


class OffendersChanged(Exception):
    """The offenders differ from ``KNOWN``: not the expected failure of the xfail mark."""


def _param(check):
    marks = []
    if KNOWN[check]:
        marks = pytest.mark.xfail(
            strict=True,
            raises=AssertionError,
            reason=f"known offenders, being removed: {KNOWN[check]}",
        )
    return pytest.param(check, marks=marks, id=check)


@pytest.mark.parametrize("check", [_param(c) for c in CHECKS])
def test_architecture(check):
    found = CHECKS[check]()
    if found != KNOWN[check]:
        fixed = [x for x in KNOWN[check] if x not in found]
        new = [x for x in found if x not in KNOWN[check]]
        raise OffendersChanged(
            f"{check}: fixed {fixed} (remove them from KNOWN, and the mark if it is empty); "
            f"new {new} (fix them)"
        )
    assert not found, f"{check}: {found}"


def test_cycles_are_found_with_function_level_and_relative_imports(tmp_path):
    """A package whose __init__ imports a submodule inside a function, and the submodule
    imports the package back with ``from . import``: one cycle; an absolute import of a
    sibling and a plain module import make no cycle."""
    pkg = tmp_path / "beamfx"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("def f():\n    from . import a\n")
    (pkg / "sub" / "a.py").write_text("from . import f\nfrom ..b import g\n")
    (pkg / "b.py").write_text("import beamfx.sub.a as _a  # noqa\n")
    graph = arch.import_graph(tmp_path)
    assert graph["beamfx.sub"] == ["beamfx.sub.a"]
    assert graph["beamfx.sub.a"] == ["beamfx.b", "beamfx.sub"]
    assert arch.cycles(graph) == [["beamfx.b", "beamfx.sub", "beamfx.sub.a"]]
    (pkg / "b.py").write_text("import numpy\n")
    assert arch.cycles(arch.import_graph(tmp_path)) == [["beamfx.sub", "beamfx.sub.a"]]


def test_long_functions_are_measured_from_def_to_last_line(tmp_path):
    pkg = tmp_path / "beamfx"
    pkg.mkdir()
    method = "        x = 1\n" * 79  # def line + 79 = 80 lines: allowed
    (pkg / "m.py").write_text(
        f"class C:\n    def ok(self):\n{method}\n\ndef long():\n" + "    x = 1\n" * 80
    )
    found = arch.long_functions(tmp_path)
    assert [(f.id, f.line, f.length) for f in found] == [("beamfx/m.py::long", 84, 81)]
