"""``probes.csv`` and ``probes.jsonl`` of a transient run: a row and a line per accepted step.

The rows are kept as the numbers of each step and written in blocks (rank 0): at every frame
step (:mod:`~beamfx.analyses.transient_run` flushes there), before every checkpoint (a
restart finds the rows up to it), once at least :data:`FLUSH_SECONDS` of wall time have passed
since the last block, at the end, and when the run fails or is stopped by a signal (the
history is closed then). A block is formatted by one format operation over all its numbers
(``{:.12g}`` in the csv, ``repr`` in the jsonl, as ``json.dumps`` writes a float), so the
files hold the same text, byte for byte, as a line formatted per step. A process killed
outright loses at most the rows since the last block.
"""

import json
import math
import time

import numpy as np

ENERGY_KEYS = (
    "kinetic",
    "strain",
    "work_loads",
    "work_supports",
    "dissipated_damping",
    "numerical",
)
PROBE_KEYS = ("position", "displacement", "rotation_vector_unwrapped")
FLUSH_SECONDS = 2.0  # the rows are on disk at most this much wall time after their step


def columns(probes):
    """The header of ``probes.csv``: the step's numbers, each probe's, the energies."""
    cols = ["step", "time", "dt", "iterations", "cutbacks"]
    for name in probes:
        cols += [f"{name}_{c}" for c in ("x", "y", "z", "ux", "uy", "uz")]
        cols += [f"{name}_rot_{c}" for c in ("x", "y", "z")]
    return cols + list(ENERGY_KEYS)


def _line_format(names, energy_keys):
    """The %-format of a probes.jsonl line (``json.dumps`` of the entry, its numbers as
    ``%r``) for probes ``names`` and a flat energy dictionary with ``energy_keys``."""

    def key(k):
        return json.dumps(k).replace("%", "%%")

    vector = "[%r, %r, %r]"
    probe = ", ".join(f"{key(k)}: {vector}" for k in PROBE_KEYS)
    probes = ", ".join(f"{key(n)}: {{{probe}}}" for n in names)
    energy = ", ".join(f"{key(k)}: %r" for k in energy_keys)
    head = ", ".join(f"{key(k)}: %r" for k in ("step", "time", "dt", "iterations"))
    return f"{{{head}, {key('probes')}: {{{probes}}}, {key('energy')}: {{{energy}}}}}\n"


class History:
    """``probes.csv`` and ``probes.jsonl``: one row per accepted step (rank 0), kept and
    written in blocks (see the module docstring).

    Args:
        folder: the output folder.
        probes: ``{probe name: point name}``.
        comm: the run's communicator (rank 0 writes).
        t_restart: the checkpoint's time on a restart: the rows after it are cut away.
    """

    def __init__(self, folder, probes, comm, t_restart=None):
        self.csv, self.jsonl = folder / "probes.csv", folder / "probes.jsonl"
        self.probes, self.root = probes, comm.rank == 0
        self.files, self.rows, self.formats = None, [], {}
        self.flushed = time.perf_counter()
        if not self.root:
            return
        header = ",".join(columns(probes))
        self.row_format = ",".join(["{:.12g}"] * header.count(",")) + ",{:.12g}\n"
        if t_restart is None:
            self.csv.write_text(header + "\n")
            self.jsonl.write_text("")
        else:
            self._truncate(header, t_restart * (1 + 1e-12))
        self.files = (self.csv.open("a"), self.jsonl.open("a"))

    def _truncate(self, header, t_max):
        """Keep what was written up to the checkpoint at ``t_max``."""
        rows = self.csv.read_text().splitlines() if self.csv.exists() else [header]
        keep = [r for r in rows[1:] if _row_time(r, header.count(",") + 1) <= t_max]
        self.csv.write_text("\n".join([header, *keep]) + "\n")
        lines = self.jsonl.read_text().splitlines() if self.jsonl.exists() else []
        keep = [x for x in lines if _entry_time(x) <= t_max]
        self.jsonl.write_text("".join(x + "\n" for x in keep))

    def add(self, r, values):
        """The row of step record ``r`` with the tracked probe ``values`` (kept; written with
        the next block)."""
        if not self.root:
            return
        points = [values[at] for at in self.probes.values()]
        self.rows.append((r.step, r.time, r.dt, r.iterations, r.cutbacks, points, r.energy))
        if time.perf_counter() - self.flushed >= FLUSH_SECONDS:
            self.flush()

    def flush(self):
        """Write the rows kept as one block and flush the probe files (rank 0)."""
        if self.files is None:
            return
        if self.rows:
            csv, jsonl = self._block(self.rows)
            self.files[0].write(csv)
            self.files[1].write(jsonl)
            self.rows = []
        for f in self.files:
            f.flush()
        self.flushed = time.perf_counter()

    def _block(self, rows):
        """(csv text, jsonl text) of ``rows``."""
        numbers, formats, values = [], [], []
        for step, t, dt, iterations, cutbacks, points, energy in rows:
            flat = []
            for v in points:
                flat += v["position"]
                flat += v["displacement"]
                flat += v["rotation_vector_unwrapped"]
            numbers += (step, t, dt, iterations, cutbacks, *flat)
            numbers += [energy[k] for k in ENERGY_KEYS]
            spent = list(energy.values())
            plain = all(type(e) is float for e in spent)  # (a sum overflowing: the json path)
            if plain and math.isfinite(t + dt + sum(flat) + sum(spent)):
                keys = tuple(energy)
                if keys not in self.formats:
                    self.formats[keys] = _line_format(self.probes, keys)
                formats.append(self.formats[keys])
                values += (step, t, dt, iterations, *flat, *spent)
            else:  # lists (a free body's momenta) or non-finite values: as json writes them
                formats.append(_entry(self.probes, step, t, dt, iterations, points, energy))
        csv = (self.row_format * len(rows)).format(*numbers)
        return csv, "".join(formats) % tuple(values)

    def close(self):
        """Write the rows kept and close the probe files (rank 0)."""
        self.flush()
        for f in self.files or ():
            f.close()
        self.files = None


def _entry(probes, step, t, dt, iterations, points, energy):
    """The jsonl line of a step through ``json.dumps``, its ``%`` doubled (a format's text)."""
    entry = {"step": step, "time": t, "dt": dt, "iterations": iterations, "probes": {}}
    for name, v in zip(probes, points):
        entry["probes"][name] = {k: v[k] for k in PROBE_KEYS}
    entry["energy"] = energy
    return (json.dumps(entry) + "\n").replace("%", "%%")


def _row_time(row, columns):
    """The time of a probes.csv row; infinite for a row cut short (a killed run's last)."""
    cells = row.split(",")
    try:
        return float(cells[1]) if len(cells) == columns else np.inf
    except ValueError:
        return np.inf


def _entry_time(line):
    """The time of a probes.jsonl line; infinite for a line cut short."""
    try:
        return float(json.loads(line)["time"])
    except (ValueError, KeyError, TypeError):
        return np.inf
