"""Fuzz of ``beamfx check`` with malformed and hostile scenes (issue 17).

A few hundred scenes are generated from one base scene that uses most keys: every leaf key
(and every component of a vector) is set to NaN, ±inf, -1, 0, 1e300, a huge integer, a
string, a bool, a list or a table, or removed; expressions are replaced by hostile ones
(``__import__``, ``10**10**10``, deep nesting, lambda, attributes); the gmsh curve's file by
hostile paths (devices, ``..``, absolute, FIFOs, links, a ``.geo`` with ``SystemCall``); sizes
by huge ones; the TOML by deep nesting and bytes that are not UTF-8. Each scene goes through
:func:`beamfx.runner.check_scene` (what ``beamfx check`` calls; a few through the command
itself) with a time limit, and must either pass with only finite numbers in its model or be
refused by a :class:`SceneError` that names the file and the key path, with no traceback,
nothing executed and nothing written outside the test's folder.
"""

import copy
import json
import math
import os
import re
import signal
import subprocess
import sys
from dataclasses import fields, is_dataclass
from pathlib import Path

import pytest

from beamfx.runner import check_scene
from beamfx.scene import SceneError, Sweep

SECONDS = 5  # per scene; check is far below (about 10 ms), a hang or a runaway loop is not
GEO = (
    "Point(1) = {0, 0, 0};\nPoint(2) = {0, 1, 0};\nPoint(3) = {1, 1, 0};\nCircle(1) = {1, 2, 3};\n"
)
BASE = {
    "material": {"E": 2.1e11, "nu": 0.3, "rho": 7850.0},
    "beams": [
        {
            "name": "bend",
            "curve": {
                "shape": "arc",
                "start": [0, 0, 0],
                "start_tangent": [0, 1, 0],
                "centre": [1, 0, 0],
                "angle_deg": 90,
            },
            "section": {"type": "rectangle", "h": "0.02 * (1 - 0.2 * s / L)", "w": 0.01},
            "elements": 4,
            "degree": 2,
            "twist_deg": 10.0,
        },
        {
            "name": "coil",
            "curve": {
                "shape": "helix",
                "centre": [1, 0.8, 0],
                "axis": [0, 0, 1],
                "radius": 0.2,
                "pitch": 0.1,
                "turns": 1.5,
                "start_direction": [0, 1, 0],
            },
            "section": {
                "type": "general",
                "EA": 1e6,
                "GA_y": 1e5,
                "GA_z": 1e5,
                "GJ": 10.0,
                "EI_y": 20.0,
                "EI_z": 20.0,
                "rho_A": 1.0,
                "rho_I": [0.1, 0.05, 0.05],
            },
            "elements": 6,
        },
        {
            "name": "quarter",
            "curve": {"shape": "gmsh", "file": "quarter.geo"},
            "section": {"type": "tube", "d": 0.05, "d_inner": 0.04, "shear_factor": 0.5},
            "elements": 3,
        },
    ],
    "supports": [
        {"at": "bend:start", "fix": "all", "displacement": [0, 0, 0.001]},
        {"at": "quarter:start", "fix": ["ux", "uy", "uz", "rx", "ry", "rz"]},
    ],
    "loads": [
        {"at": "bend:end", "force": [0, 0, 100], "moment": [1, 0, 0], "history": "min(t, 1)"},
        {"beam": "coil", "force_per_length": [0, 0, -1]},
        {"gravity": [0, 0, -9.81]},
    ],
    "springs": [{"at": "coil:end", "stiffness": [1e3, 0, 0], "rotational": [0, 0, 10]}],
    "masses": [{"at": "quarter:end", "mass": 2.0, "inertia": [0.1, 0.1, 0.2]}],
    "probes": [{"name": "tip", "at": "bend:end"}],
    "analysis": {"type": "static", "steps": 4},
    "output": {"dir": "out", "every": 1},
}
ANALYSES = {
    "transient": {
        "type": "transient",
        "t_end": 1.0,
        "dt": 0.01,
        "dt_min": 1e-4,
        "rho_inf": 0.8,
        "damping": {"mass": 0.1, "stiffness": 0.001},
    },
    "arclength": {
        "type": "arclength",
        "max_steps": 20,
        "target_load_factor": 2.0,
        "arc_length": 0.1,
    },
    "modal": {"type": "modal", "modes": 4, "target_hz": 0.0, "steps": 2},
}
HOSTILE = [math.nan, math.inf, -math.inf, -1, 0, 1e300, 10**30, "x", True, [], {}]
COMPONENT = [math.nan, math.inf, -1, 10**30, "x"]  # for each component of a vector
EXPRESSIONS = [
    "__import__('os').system('touch PWNED')",
    "10**10**10",
    "9" * 500 + "**9",
    "(" * 200 + "s" + ")" * 200,
    "-" * 3000 + "s",
    "+".join(["s"] * 600),
    "(lambda: 1)()",
    "s.__class__",
    "().__class__.__bases__[0]",
    "[s for s in (1,)]",
    "'a' * 10**9",
    "open('/etc/passwd')",
    "max(s, key=1)",
    "0 * s / 0",
    "sqrt(-1 - s)",
    "exp(1e6 + s)",
]
#: keys whose message may name a neighbour (the check is about the pair)
RELATED = {
    "beams[0].curve.start": ("start_tangent", "centre"),
    "beams[0].curve.centre": ("start_tangent",),
    "beams[1].curve.axis": ("start_direction",),
    "beams[2].section.d": ("d_inner",),
    "supports[0].displacement": ("fix",),
    "analysis.t_end": ("dt",),
}


def toml_value(v):
    """One TOML inline value (NaN and infinities in TOML's spelling)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float) and not math.isfinite(v):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, int | float):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(map(toml_value, v)) + "]"
    return "{ " + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + " }"


def toml_text(data):
    """A scene file of ``data``: top-level tables and arrays of tables, inline values below."""
    lines = []
    for key, value in data.items():
        if isinstance(value, dict):
            lines += [f"[{key}]"] + [f"{json.dumps(k)} = {toml_value(v)}" for k, v in value.items()]
        elif isinstance(value, list) and value and all(isinstance(x, dict) for x in value):
            for x in value:
                lines += [f"[[{key}]]"] + [
                    f"{json.dumps(k)} = {toml_value(v)}" for k, v in x.items()
                ]
        else:
            lines.insert(0, f"{json.dumps(key)} = {toml_value(value)}")
    return "\n".join(lines) + "\n"


def leaves(node, path=""):
    """(key path as in the messages, container, key) of every value of the base scene."""
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in items:
        if isinstance(node, list):
            p = f"{path}[{k}]"
        else:
            p = f"{path}.{k}" if path else k
        if isinstance(v, dict) or (isinstance(v, list) and v and isinstance(v[0], dict)):
            yield from leaves(v, p)
        else:
            yield p, node, k
            if isinstance(v, list) and len(v) == 3:  # a vector: each component too
                for i in range(3):
                    yield f"{p}#{i}", v, i


def mutated(data, path, value):
    """A deep copy of ``data`` with the leaf at ``path`` (from :func:`leaves`) set or removed."""
    data = copy.deepcopy(data)
    for p, node, key in leaves(data):
        if p == path:
            if value is REMOVE:
                del node[key]
            else:
                node[key] = value
            return data
    raise KeyError(path)


REMOVE = object()


def tables(node, path=""):
    """(key path, container, key) of every table and array of tables of the base scene."""
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in items:
        p = f"{path}[{k}]" if isinstance(node, list) else (f"{path}.{k}" if path else k)
        if isinstance(v, dict) or (isinstance(v, list) and v and isinstance(v[0], dict)):
            yield p, node, k
            yield from tables(v, p)


def table_cases():
    """Every table or array of tables replaced by a value of another shape."""
    out = []
    for path, _, _ in list(tables(BASE)):
        for value in [5, "x", [], {}, [1, 2], [{}], math.nan, True]:
            data = copy.deepcopy(BASE)
            node, key = next((n, k) for p, n, k in tables(data) if p == path)
            node[key] = value
            out.append((f"{path}={value!r}", data, path, True))
    return out


def cases():
    """(id, data, the key path the message must name, whether a key of its table will do)."""
    out = []
    for name, analysis in [("static", BASE["analysis"]), *ANALYSES.items()]:
        base = {**BASE, "analysis": analysis}
        for path, _, _ in leaves(base):
            if name != "static" and not path.startswith("analysis"):
                continue  # the other keys are fuzzed once, with the static analysis
            key = path.split("#")[0]
            for value in [*HOSTILE, REMOVE] if "#" not in path else COMPONENT:
                label = f"{name}:{path}={'<removed>' if value is REMOVE else repr(value)}"
                out.append((label, mutated(base, path, value), key, value is REMOVE))
    for expr in EXPRESSIONS:
        for key in ("beams[0].section.h", "loads[0].history"):
            out.append((f"{key}={expr[:40]}", mutated(BASE, key, expr), key, False))
    return out + table_cases()


def finite(obj):
    """Every number reachable from a model dataclass is finite."""
    if isinstance(obj, float):
        return math.isfinite(obj)
    if isinstance(obj, tuple | list):
        return all(finite(x) for x in obj)
    if is_dataclass(obj):
        return all(finite(getattr(obj, f.name)) for f in fields(obj))
    return True


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang(f"check took longer than {SECONDS} s")


def check(path, seconds=SECONDS):
    """check_scene under a time limit: the scene, or the SceneError."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(seconds)
    try:
        return check_scene(path)
    except SceneError as e:
        return e
    except Exception as e:  # noqa: BLE001  (reported with the scene's label by the caller)
        return AssertionError(f"{type(e).__name__}: {e}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The scenes' folder: the base's .geo next to them, a marker file that must not appear."""
    root = tmp_path_factory.mktemp("fuzz")
    scenes = root / "scenes"
    scenes.mkdir()
    (scenes / "quarter.geo").write_text(GEO)
    return scenes


def _named(result, file, key, removed=False):
    """Does the message name the file and the key (or a key it is checked against)?"""
    message = str(result)
    table, _, leaf = key.rpartition(".")
    named = [key, *(f"{table}.{k}" for k in RELATED.get(key, ()))]
    if leaf == "name":  # a renamed beam: the points on it name it no more
        named += ["names no beam", "is no beam"]
    if ".curve." in key:  # a moved or resized curve: joints, supports, the merge tolerance
        named += [": supports: supports leave", *(f"beams[{i}].curve" for i in range(4))]
    if removed:  # a key left out or a table replaced: a key of the table may be named
        named += [f"{file}: {table}.", f"{file}: {key}"]
    return message.startswith(f"{file}: ") and any(n in message for n in named)


def _assert_named(result, file, key):
    if not _named(result, file, key):
        pytest.fail(f"{key} not named: {result}")


def test_base_scene_passes(folder):
    path = folder / "base.toml"
    path.write_text(toml_text(BASE))
    scene = check(path)
    assert not isinstance(scene, Exception), scene
    assert len(scene.model.beams) == 3 and finite(scene.model)


def test_fuzzed_keys_are_refused_by_name_or_pass_finite(folder):
    """Several hundred scenes; each refused with file and key, or valid with finite numbers."""
    generated, refused, wrong = 0, 0, []
    for i, (label, data, key, loose) in enumerate(cases()):
        path = folder / f"k{i}.toml"
        path.write_text(toml_text(data))
        result = check(path)
        generated += 1
        if isinstance(result, SceneError):
            refused += 1
            if not _named(result, path, key, removed=loose):
                wrong.append(f"{label}: {result}")
        elif isinstance(result, Exception):
            wrong.append(f"{label}: {result}")
        elif not finite(result.model):
            wrong.append(f"{label}: passed with a number that is not finite")
        path.unlink()
    assert not wrong, "\n".join(wrong)
    assert generated > 300 and refused > 0.6 * generated, (generated, refused)
    assert not (folder / "PWNED").exists() and not Path("PWNED").exists()


def _geo_cases(folder, marker):
    """(file value, extra files to make) of hostile gmsh curve files."""
    outside = folder.parent / "outside.geo"
    outside.write_text(GEO)
    (folder / "link.geo").symlink_to("/dev/zero")
    (folder / "up.geo").symlink_to(outside)
    os.mkfifo(folder / "fifo.geo")
    (folder / "dir.geo").mkdir()
    (folder / "latin1.geo").write_bytes(b"// caf\xe9\n" + GEO.encode())
    (folder / "text.txt").write_text(GEO)
    calls = {
        "system.geo": f'SystemCall "touch {marker}";\n',
        "nonblocking.geo": f'NonBlockingSystemCall "touch {marker}";\n',
        "renamed.geo": f'SystemCall = 1;\nSystemCall "touch {marker}";\n',
        "include.geo": f'Include "{outside}";\n',
        "merge.geo": 'Merge "/etc/passwd";\n',
        "save.geo": f'Save "{marker}";\n',
        "printf.geo": f'Printf("x") > "{marker}";\n',
        "loop.geo": "For i In {1:1e9}\nEndFor\n",
        "option.geo": 'General.FileName = "x";\n',
        "solver.geo": f'Solver.Executable0 = "touch {marker}";\nOnelabRun("x");\n',
        "sleep.geo": "Sleep 100;\n",
        "exit.geo": "Exit;\n",
    }
    for name, text in calls.items():
        (folder / name).write_text(GEO + text)
    names = ["/dev/zero", "/dev/urandom", "../../etc/passwd", "/etc/shadow", "/etc/passwd"]
    names += [str(outside), "../outside.geo", "link.geo", "up.geo", "fifo.geo", "dir.geo"]
    names += ["latin1.geo", "text.txt", "missing.geo", "", "quarter.geo\0x", *calls]
    return names


def test_hostile_gmsh_files_are_refused_and_run_nothing(folder):
    marker = folder.parent / "SYSTEMCALL_RAN"
    names = _geo_cases(folder, marker)
    for i, name in enumerate(names):
        data = copy.deepcopy(BASE)
        data["beams"][2]["curve"]["file"] = name
        path = folder / f"g{i}.toml"
        path.write_text(toml_text(data))
        result = check(path)
        assert isinstance(result, SceneError), (name, result)
        _assert_named(result, path, "beams[2].curve.file")
        if name.endswith(".geo") and name in ("system.geo", "renamed.geo", "loop.geo"):
            assert "not allowed" in str(result), str(result)
    assert not marker.exists()
    # the limit on file sizes, and a file outside allowed when the scene says so
    data = copy.deepcopy(BASE)
    data["limits"] = {"max_file_mb": 1e-5}
    (folder / "small.toml").write_text(toml_text(data))
    assert "max_file_mb" in str(check(folder / "small.toml"))
    data = copy.deepcopy(BASE)
    data["limits"] = {"files_outside": True}
    data["beams"][2]["curve"]["file"] = "../outside.geo"
    (folder / "outside.toml").write_text(toml_text(data))
    assert not isinstance(check(folder / "outside.toml"), Exception)


def _sized(edit):
    data = copy.deepcopy(BASE)
    edit(data)
    return data


SIZES = [
    (lambda d: d["beams"][0].update(elements=100_000_000), "beams[0].elements", "max_unknowns"),
    (lambda d: d["analysis"].update(steps=10**12), "analysis.steps", "at most"),
    (
        lambda d: d.update(analysis={**ANALYSES["modal"], "modes": 10**8}),
        "analysis.modes",
        "max_count",
    ),
    (
        lambda d: d.update(analysis={**ANALYSES["transient"], "dt": 1e-300}),
        "analysis.dt",
        "max_count",
    ),
    (
        lambda d: d.update(analysis={**ANALYSES["arclength"], "max_steps": 10**9}),
        "analysis.max_steps",
        "max_count",
    ),
    (lambda d: d["beams"][0]["curve"].update(angle_deg=720), "beams[0].curve.angle_deg", "360"),
    (lambda d: d["beams"][1]["curve"].update(pitch=0.0, turns=3), "beams[1].curve.turns", "itself"),
    (
        lambda d: d["beams"].append({**d["beams"][0], "name": "again", "elements": 4}),
        "beams[3].curve",
        "itself",
    ),
    (
        lambda d: d["beams"][0]["curve"].update(start_tangent=[-1, 0, 0]),
        "beams[0].curve.start_tangent",
        "parallel",
    ),
    (
        lambda d: d["beams"][1]["curve"].update(start_direction=[0, 0, 2]),
        "beams[1].curve.start_direction",
        "parallel",
    ),
    (
        lambda d: d["beams"][0].update(
            curve={"shape": "line", "start": [0, 0, 0], "direction": [1, 0, 0], "length": math.inf}
        ),
        "beams[0].curve.length",
        "finite",
    ),
    (
        lambda d: d["beams"][0].update(
            curve={"shape": "spline", "points": [[0, 0, 0], [0, 0, 0], [1, 0, 0]]}
        ),
        "beams[0].curve.points",
        "equal",
    ),
    (
        lambda d: d["beams"][0].update(
            curve={"shape": "spline", "points": [[0, 0, 0], [1, "a", 0]]}
        ),
        "beams[0].curve.points[1]",
        "finite",
    ),
    (lambda d: d["loads"].append({"gravity": [0, 0, -1]}), "loads[3].gravity", "twice"),
    (
        lambda d: d.update(
            sweep=[
                {"key": "analysis.steps", "values": list(range(1, 1001))},
                {"key": "loads[0].force", "values": [[0, 0, i] for i in range(1000)]},
            ]
        ),
        "sweep",
        "max_members",
    ),
    (lambda d: d.update(limits={"max_unknowns": math.nan}), "limits.max_unknowns", "integer"),
    (
        lambda d: (
            d.update(analysis=ANALYSES["transient"])
            or d["loads"][0].update(history="1 / (t - 0.75)")
        ),
        "loads[0].history",
        "not finite at t = 0.75",
    ),
    (
        lambda d: d["beams"].extend({**d["beams"][0], "name": f"b{i}"} for i in range(5000)),
        "beams",
        "max_beams",
    ),
    (
        lambda d: (
            d.update(limits={"max_unknowns": 20_000})
            or d["beams"][0].update(
                curve={"shape": "polyline", "points": [[i, i % 2, 0] for i in range(2000)]}
            )
        ),
        "beams[0].curve.points",
        "kinks",
    ),
    (
        lambda d: d.update(
            analysis={"type": "rotating", "speeds_rad_s": [1.0] * 2000}, limits={"max_count": 1000}
        ),
        "analysis.speeds_rad_s",
        "max_count",
    ),
]


@pytest.mark.parametrize("edit, key, words", SIZES, ids=[s[1] + ":" + s[2] for s in SIZES])
def test_sizes_and_shapes_are_refused_by_their_key(folder, edit, key, words):
    path = folder / f"size_{abs(hash(key)) % 10**8}.toml"
    path.write_text(toml_text(_sized(edit)))
    result = check(path)
    assert isinstance(result, SceneError), result
    _assert_named(result, path, key)
    assert words in str(result), str(result)


def test_a_limit_raised_by_the_scene_allows_the_size(folder):
    data = _sized(lambda d: d["beams"][0].update(elements=200_000))
    path = folder / "raised.toml"
    path.write_text(toml_text(data))
    assert "max_unknowns" in str(check(path))
    data["limits"] = {"max_unknowns": 3_000_000}
    path.write_text(toml_text(data))
    assert not isinstance(check(path), Exception)


TEXTS = {
    "deep_array": "a = " + "[" * 5000 + "]" * 5000 + "\n",
    "deep_table": "a = " + "{b = " * 3000 + "1" + "}" * 3000 + "\n",
    "nested_33": "a = " + "[" * 40 + "1" + "]" * 40 + "\n",
    "two_material_tables": "[material]\nE = 1.0\n[material]\nE = 2.0\n",
    "not_toml": "[beams\n",
    "nan_key": "x = nan\n",
    "too_large": "# " + "x" * 5_000_000 + "\n",
}


@pytest.mark.parametrize("name", sorted(TEXTS))
def test_malformed_files_are_refused_naming_the_file(folder, name):
    path = folder / f"{name}.toml"
    path.write_text(TEXTS[name])
    result = check(path)
    assert isinstance(result, SceneError) and str(result).startswith(f"{path}: "), result


def test_bytes_that_are_not_utf8_and_devices_name_the_file(folder):
    path = folder / "latin1.toml"
    path.write_bytes(toml_text(BASE).encode() + b"# caf\xe9\n")
    assert re.match(rf"{re.escape(str(path))}: not UTF-8", str(check(path)))
    assert str(check("/dev/zero")).startswith("/dev/zero: not a regular file")


def test_a_large_sweep_is_checked_by_its_axes(folder):
    """10⁴ members (100 x 100): read and checked in about a second, not one scene each."""
    data = copy.deepcopy(BASE)  # one beam: 199 members are read, each in a few ms
    data["beams"] = data["beams"][:1]
    data.update(supports=data["supports"][:1], springs=[], masses=[])
    data["loads"] = data["loads"][:1]
    data["sweep"] = [
        {"key": "analysis.steps", "values": list(range(1, 101))},
        {"key": "loads[0].force", "values": [[0, 0, i] for i in range(100)]},
    ]
    path = folder / "sweep.toml"
    path.write_text(toml_text(data))
    sweep = check(path, seconds=30)  # 199 scenes read
    assert isinstance(sweep, Sweep) and len(sweep.members) == 10_000
    assert len(sweep.validated) == 1 + 99 + 99
    assert sweep.members[5050].scene.model.point_loads[0].force == (0.0, 0.0, 50.0)
    data["sweep"][0]["values"][57] = math.nan
    path.write_text(toml_text(data))
    message = str(check(path, seconds=30))
    assert "sweep member 5700" in message and "analysis.steps = nan" in message, message


def test_gmsh_writes_no_preference_file(folder, tmp_path):
    """gmsh's FLTK rewrote fltk.prefs in /etc and the home folder on every curve: in a fresh
    home folder, reading a curve leaves it empty (the same call writes the /etc file)."""
    home = tmp_path / "home"
    home.mkdir()
    code = (
        "from beamfx.geometry import curve_from_gmsh; print(curve_from_gmsh('quarter.geo').length)"
    )
    env = {**os.environ, "HOME": str(home), "PYTHONPATH": str(Path(__file__).parents[2])}
    p = subprocess.run(
        [sys.executable, "-c", code],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert float(p.stdout) == pytest.approx(math.pi / 2, rel=1e-8)
    assert list(home.iterdir()) == []


def test_the_command_says_what_is_wrong_without_a_traceback(folder):
    """A few scenes through ``beamfx check`` itself: exit 2, one line naming file and key."""
    cases = {
        "nan.toml": mutated(BASE, "beams[0].section.w", math.nan),
        "expr.toml": mutated(BASE, "beams[0].section.h", "10**10**10"),
        "geo.toml": mutated(BASE, "beams[2].curve.file", "/dev/zero"),
    }
    for name, data in cases.items():
        (folder / name).write_text(toml_text(data))
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])}
    for name in cases:
        p = subprocess.run(
            [sys.executable, "-m", "beamfx.cli", "check", str(folder / name)],
            check=False,
            capture_output=True,
            text=True,
            timeout=120,
            env=env,
        )
        assert p.returncode == 2, p.stderr
        assert "Traceback" not in p.stderr and p.stderr.startswith(
            f"beamfx: error: {folder / name}: beams["
        )


#: a frame scene ([[frames]] from a mesh file, beamfx.scene.frames) with every frame key
FRAME_BASE = {
    "material": {"E": 2.1e11, "nu": 0.3, "rho": 7850.0},
    "frames": [
        {
            "name": "p",
            "mesh": "portal.msh",
            "elements": 1,
            "degree": 2,
            "members": [
                {"group": "columns", "section": {"type": "tube", "d": 0.1, "d_inner": 0.08}},
                {
                    "group": "beam",
                    "section": {"type": "rectangle", "h": 0.2, "w": 0.1},
                    "orientation": [0, 1, 1],
                    "twist_deg": 5.0,
                },
            ],
            "supports": [{"group": "feet", "fix": "all"}],
            "loads": [{"group": "knees", "force": [1e3, 0, 0], "moment": [0, 0, 1.0]}],
            "probes": [{"group": "knees", "name": "k"}],
            "offsets": [{"group": "beam", "end": "both", "offset": [0, 0.1, 0.2]}],
            "joints": [
                {
                    "group": "knees",
                    "releases": ["ry"],
                    "axes": {"x": [1, 0, 0], "y": [0, 1, 0]},
                    "members": "beam",
                }
            ],
        }
    ],
    "analysis": {"type": "static", "steps": 2},
}


def test_fuzzed_frame_keys_are_refused_by_name_or_pass_finite(folder):
    """Every key of a [[frames]] scene (members, supports, loads, probes, offsets, joints) set to
    hostile values or removed: refused naming the file and the key, or valid and finite."""
    from beamfx.geometry.line_mesh import write_line_mesh

    points = [[0, 0, 0], [0, 0, 3], [4, 0, 3], [4, 0, 0]]
    groups, nodes = {"columns": [0, 2], "beam": [1]}, {"feet": [0, 3], "knees": [1, 2]}
    write_line_mesh(folder / "portal.msh", points, [[0, 1], [1, 2], [3, 2]], groups, nodes)
    path = folder / "frame.toml"
    path.write_text(toml_text(FRAME_BASE))
    scene = check(path)
    assert not isinstance(scene, Exception), scene
    assert len(scene.model.releases) == 2 and finite(scene.model)
    generated, wrong = 0, []
    for p, _, _ in leaves(FRAME_BASE):
        for value in [*HOSTILE, REMOVE] if "#" not in p else COMPONENT:
            path = folder / f"f{generated}.toml"
            path.write_text(toml_text(mutated(FRAME_BASE, p, value)))
            result, generated = check(path), generated + 1
            label = f"{p}={'<removed>' if value is REMOVE else repr(value)}"
            if isinstance(result, SceneError):
                if not _named(result, path, p.split("#")[0], removed=value is REMOVE):
                    wrong.append(f"{label}: {result}")
            elif isinstance(result, Exception) or not finite(result.model):
                wrong.append(f"{label}: {result if isinstance(result, Exception) else 'nan'}")
            path.unlink()
    assert not wrong, "\n".join(wrong)
    assert generated > 250, generated
