"""``probes.csv`` and ``probes.jsonl`` of a transient run: a row and a line per accepted step.

At every step only the step's numbers and the probes' raw kinematics are kept
(:class:`~beamfx.io.probe_blocks.ProbeBlocks`, a copy of a few numbers); the rows are made and
written in blocks (rank 0) at every frame step (:mod:`~beamfx.analyses.transient_run` flushes
there), before every checkpoint (a restart finds the rows up to it), when a block is full,
once at least :data:`FLUSH_SECONDS` of wall time have passed since the last block, at the end,
and when the run fails or is stopped by a signal (the history is closed then). Flushing is
collective (the probes' values are gathered on rank 0). A block is formatted by one format
operation over all its numbers (``{:.12g}`` in the csv, ``repr`` in the jsonl, as
``json.dumps`` writes a float), so the files hold the same text, byte for byte, as a line
formatted per step. A process killed outright loses at most the rows since the last block.
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
CLOCK_STEPS = 16  # with several ranks, rank 0's clock is asked every this many steps


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
        blocks: the :class:`~beamfx.io.probe_blocks.ProbeBlocks` of the probes' points.
        t_restart: the checkpoint's time on a restart: the rows after it are cut away.
    """

    def __init__(self, folder, probes, comm, blocks, t_restart=None):
        self.csv, self.jsonl = folder / "probes.csv", folder / "probes.jsonl"
        self.probes, self.root, self.comm, self.blocks = probes, comm.rank == 0, comm, blocks
        self.columns = [blocks.points.index(at) for at in probes.values()]
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

    def add(self, r):
        """The row of step record ``r`` and the probes' state now (kept; written with the next
        block, which may be now). Collective."""
        self.blocks.record()
        if self.root:
            self.rows.append((r.step, r.time, r.dt, r.iterations, r.cutbacks, r.energy))
        if self.blocks.full or self._clock_due():
            self.flush()

    def _clock_due(self):
        """Whether :data:`FLUSH_SECONDS` have passed since the last block: rank 0's clock,
        asked at every step on one rank, every :data:`CLOCK_STEPS` kept steps on several
        (broadcast: the flush is collective)."""
        if self.comm.size == 1:
            return time.perf_counter() - self.flushed >= FLUSH_SECONDS
        if self.blocks.count % CLOCK_STEPS:
            return False
        due = self.root and time.perf_counter() - self.flushed >= FLUSH_SECONDS
        return self.comm.bcast(due, root=0)

    def flush(self):
        """Make the rows kept into a block, write it and flush the probe files (rank 0).
        Collective."""
        table = self.blocks.drain()
        if self.files is None:
            return
        rows, self.rows = self.rows, []  # (taken with their table: a failed write loses both)
        if rows:
            csv, jsonl = self._block(rows, table[:, self.columns])
            self.files[0].write(csv)
            self.files[1].write(jsonl)
        for f in self.files:
            f.flush()
        self.flushed = time.perf_counter()

    def _block(self, rows, table):
        """(csv text, jsonl text) of ``rows`` and their probes' ``table`` (rows, probes, 9)."""
        numbers, formats, values = [], [], []
        for (step, t, dt, iterations, cutbacks, energy), flat in zip(
            rows, table.reshape(len(rows), -1).tolist()
        ):
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
                formats.append(_entry(self.probes, step, t, dt, iterations, flat, energy))
        csv = (self.row_format * len(rows)).format(*numbers)
        return csv, "".join(formats) % tuple(values)

    def close(self, gather=True):
        """Write the rows kept and close the probe files (rank 0). Collective, unless
        ``gather`` is False (after an error that may be one rank's: with several ranks the
        rows kept since the last block are then lost, as a killed process's)."""
        if gather or self.comm.size == 1:
            self.flush()
        else:
            self.blocks.count, self.rows = 0, []
        for f in self.files or ():
            f.close()
        self.files = None


def _entry(probes, step, t, dt, iterations, flat, energy):
    """The jsonl line of a step through ``json.dumps``, its ``%`` doubled (a format's text);
    ``flat``: the probes' 9 numbers each (position, displacement, unwrapped rotation)."""
    entry = {"step": step, "time": t, "dt": dt, "iterations": iterations, "probes": {}}
    for i, name in enumerate(probes):
        v = flat[9 * i : 9 * i + 9]
        entry["probes"][name] = {k: v[3 * j : 3 * j + 3] for j, k in enumerate(PROBE_KEYS)}
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
