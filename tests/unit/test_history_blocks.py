"""The per-step output written in blocks gives the text a row-by-row writer gives (issue 15):
``probes.csv`` / ``probes.jsonl`` of a transient, and a history's one-value path."""

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from beamfx.analyses import transient_history
from beamfx.analyses.transient_history import ENERGY_KEYS, History, columns
from beamfx.scene.expr import compile_expression

SPIN = "where(t < 15, (6/15) * (t**2/2 + (15/(2*pi))**2 * (cos(2*pi*t/15) - 1)), 6*t - 45)"
ROOT = SimpleNamespace(rank=0, size=1)
PROBES = {"tip": "beam:end", 'odd %s "name"': "beam:mid"}


def _reference(probes, records):
    """(csv, jsonl) written row by row: ``{:.12g}`` per cell and ``json.dumps`` per line (the
    writer before the blocks)."""
    cols = columns(probes)
    row_format = ",".join(["{:.12g}"] * len(cols)) + "\n"
    csv, jsonl = ",".join(cols) + "\n", ""
    for r, values in records:
        row = [r.step, r.time, r.dt, r.iterations, r.cutbacks]
        entry = {"step": r.step, "time": r.time, "dt": r.dt, "iterations": r.iterations}
        entry["probes"] = {}
        for name, at in probes.items():
            v = values[at]
            row += [*v["position"], *v["displacement"], *v["rotation_vector_unwrapped"]]
            keys = ("position", "displacement", "rotation_vector_unwrapped")
            entry["probes"][name] = {k: v[k] for k in keys}
        row += [r.energy[k] for k in ENERGY_KEYS]
        entry["energy"] = r.energy
        csv += row_format.format(*row)
        jsonl += json.dumps(entry) + "\n"
    return csv, jsonl


def _records(n, rng):
    """Step records and probe values of all kinds: tiny, huge, negative, integral floats,
    non-finite values, and a free body's momenta (lists) in the energies."""
    specials = [0.0, -0.0, 1.0, 1e-300, 1e300, 123456789012.0, 0.1, math.nan, math.inf, -math.inf]
    out = []
    for i in range(n):

        def number():
            if rng.random() < 0.1:
                return specials[rng.integers(len(specials))]
            return float(rng.normal() * 10.0 ** rng.integers(-20, 20))

        energy = {k: number() for k in ENERGY_KEYS[:-1]}
        if i % 5 == 3:  # a free body: momenta before "numerical", as EnergyBalance orders them
            energy["linear_momentum"] = [number() for _ in range(3)]
            energy["angular_momentum"] = [number() for _ in range(3)]
        energy["numerical"] = number()
        values = {
            at: {k: [number() for _ in range(3)] for k in transient_history.PROBE_KEYS}
            for at in PROBES.values()
        }
        r = SimpleNamespace(step=i, time=0.0125 * i, dt=number(), iterations=int(rng.integers(1, 9)),
                            cutbacks=int(rng.integers(0, 2)), energy=energy)  # fmt: skip
        out.append((r, values))
    return out


class _Blocks:
    """A stand-in for :class:`~beamfx.io.probe_blocks.ProbeBlocks`: keeps the values handed
    to it (``pending``) at each record and drains them as the (rows, points, 9) table."""

    full = False

    def __init__(self, points):
        self.points, self.kept, self.pending = list(dict.fromkeys(points)), [], None

    @property
    def count(self):
        return len(self.kept)

    def record(self):
        self.kept.append(self.pending)

    def drain(self):
        if not self.kept:
            return None
        keys = transient_history.PROBE_KEYS
        table = [[[x for k in keys for x in v[at][k]] for at in self.points] for v in self.kept]
        self.kept = []
        return np.array(table)


def _history(folder, t_restart=None):
    return History(folder, PROBES, ROOT, _Blocks(PROBES.values()), t_restart)


def _add(history, r, values):
    history.blocks.pending = values
    history.add(r)


def test_blocks_are_the_row_by_row_text(tmp_path, monkeypatch):
    """Random records (non-finite values and momenta among them) written in blocks of several
    sizes: both files are byte for byte those written row by row."""
    records = _records(400, np.random.default_rng(3))
    history = _history(tmp_path)
    for i, (r, values) in enumerate(records):
        _add(history, r, values)
        if i % 37 == 5:  # blocks of varied sizes, as frames and checkpoints make them
            history.flush()
    history.close()
    csv, jsonl = _reference(PROBES, records)
    assert (tmp_path / "probes.csv").read_text() == csv
    assert (tmp_path / "probes.jsonl").read_text() == jsonl


def test_rows_reach_the_files_at_a_flush_or_after_the_time_limit(tmp_path, monkeypatch):
    """Rows are kept until a flush (a frame, a checkpoint), written once FLUSH_SECONDS have
    passed, and the rest when the history is closed (the end, a failure, a signal)."""
    records = _records(6, np.random.default_rng(5))
    csv = tmp_path / "probes.csv"
    history = _history(tmp_path)
    _add(history, *records[0])
    assert len(csv.read_text().splitlines()) == 1  # the header only
    history.flush()
    assert len(csv.read_text().splitlines()) == 2
    monkeypatch.setattr(transient_history, "FLUSH_SECONDS", 0.0)
    _add(history, *records[1])  # the time limit passed: written at once
    assert len(csv.read_text().splitlines()) == 3
    monkeypatch.setattr(transient_history, "FLUSH_SECONDS", 1e9)
    _add(history, *records[2])
    assert len(csv.read_text().splitlines()) == 3
    history.close()
    assert len(csv.read_text().splitlines()) == 4
    assert len((tmp_path / "probes.jsonl").read_text().splitlines()) == 3


def test_a_restart_keeps_the_rows_up_to_its_checkpoint(tmp_path):
    """A restart at a checkpoint's time keeps the rows written up to it (flushed before the
    checkpoint) and goes on after them."""
    records = _records(10, np.random.default_rng(9))
    history = _history(tmp_path)
    for r, values in records[:6]:
        _add(history, r, values)
    history.flush()  # what the checkpoint writer does first
    history.close()
    history = _history(tmp_path, t_restart=records[4][0].time)
    for r, values in records[5:]:
        _add(history, r, values)
    history.close()
    csv, jsonl = _reference(PROBES, records)
    assert (tmp_path / "probes.csv").read_text() == csv
    assert (tmp_path / "probes.jsonl").read_text() == jsonl


@pytest.mark.parametrize(
    "text", [SPIN, "t**0.5", "sqrt(t) * exp(-t)", "max(t, 2) % 3", "log(t - 1)", "t < 3"]
)
def test_history_one_value_path_is_bitwise_its_value(text):
    """``f.at(t)`` (the per-step path of set_time) is bitwise ``float(f(t))``, NaN included."""
    f = compile_expression(text, "t")
    times = np.random.default_rng(1).uniform(0.0, 30.0, 3000)
    got = np.array([f.at(t) for t in times])
    want = np.array([float(f(t)) for t in times])
    assert got.tobytes() == want.tobytes()


def test_history_one_value_path_reports_constant_errors():
    with pytest.raises(ValueError, match="1/0"):
        compile_expression("t + 1/0", "t").at(1.0)
