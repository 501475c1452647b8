"""Time series of frames: the PVD index and the frame files of every rank.

The PVD time-series index is the only XML written by hand here: VTK's wheel has no PVD
writer, and rewriting a whole index after every frame costs in proportion to the frames
written (the old writers spent 6 s of a 10 s run that way). :class:`PvdIndex` appends one
``<DataSet>`` line per frame in place of the closing tags, so a frame costs the same at the
10th and the 10 000th frame and the file is valid after each one.

A frame is ``<stem>_NNNN.vtu`` from one rank, or from several a piece ``<stem>_NNNN_R.vtu``
per rank (the cells it owns) and the summary ``<stem>_NNNN.pvtu`` from rank 0
(:mod:`beamfx.io.vtkfiles`). Rank 0 appends the index line after its own piece and the
summary, without waiting for the other ranks' pieces (a reader may for a moment find a piece
of the newest frame missing; a barrier per frame would cost more than the frame).

A run in a folder that holds an earlier run's series starts its index afresh; the earlier
frames are overwritten by the new frames of the same name, and those not written again are
deleted when the series is closed (:meth:`VtkSeries.close`, at the end of the run): deleting a
file cost 3 ms on the machine of the benchmarks, overwriting one 0.1 ms, so a re-run of the
spin-up (207 frames) deleting first spent 0.7 s on it.
"""

import os

from .vtkfiles import GridWriter, summary_template, write_summary

HEAD = '<?xml version="1.0"?>\n<VTKFile type="Collection" version="1.0" byte_order="LittleEndian">\n<Collection>\n'
TAIL = "</Collection>\n</VTKFile>\n"


def piece_names(path):
    """Files of the pieces a ``.pvtu`` lists (beside it), read from the file."""
    import xml.etree.ElementTree as ET  # only to read (a restart): not at every start-up

    folder = os.path.dirname(os.fspath(path))
    root = ET.parse(path).getroot()
    return [os.path.join(folder, p.get("Source")) for p in root.iter("Piece")]


class PvdIndex:
    """A ParaView collection (``.pvd``) appended one ``<DataSet>`` line per frame (rank 0).

    Args:
        path: the ``.pvd`` file.
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        self._file = None  # open for appending from the first append to close()

    def create(self, entries=()):
        """Start the file afresh with ``entries`` [(time, file name relative to it)]."""
        self.close()
        lines = "".join(_line(t, f) for t, f in entries)
        tmp = f"{self.path}.tmp{os.getpid()}"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(HEAD + lines + TAIL)
        os.replace(tmp, self.path)

    def append(self, time, file):
        """Add the frame ``file`` (relative to the index) at ``time``: the closing tags are
        overwritten by the new line and written again after it, and flushed (the file stays
        open between frames)."""
        if self._file is None:
            self._file = open(self.path, "r+b")  # noqa: SIM115 (closed by close())
        f = self._file
        f.seek(-len(TAIL), os.SEEK_END)
        f.write((_line(time, file) + TAIL).encode("utf-8"))
        f.flush()

    def close(self):
        """Close the file (the next :meth:`append` opens it again)."""
        if self._file is not None:
            self._file.close()
            self._file = None

    def read(self):
        """[(time, file)] of an existing index, [] if there is none."""
        if not os.path.exists(self.path):
            return []  # (a new folder: no XML parser imported, 2 ms of a process's first frame)
        import xml.etree.ElementTree as ET

        root = ET.parse(self.path).getroot()
        return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def kept_until(t_max, inclusive=True):
    """``keep(t)``: whether a frame at time ``t`` of an earlier run stays on a restart at
    ``t_max`` (relative tolerance 1e-12; the frame at ``t_max`` too if ``inclusive``), for
    every series (VTK here, XDMF in :mod:`beamfx.io.xdmf`)."""
    if inclusive:
        top = t_max * (1 + 1e-12) + 1e-300
        return lambda t: t <= top
    return lambda t: t < t_max * (1 - 1e-12)


class VtkSeries:
    """A time series ``<stem>.pvd`` of frames ``<stem>_NNNN.vtu`` (one rank) or
    ``<stem>_NNNN.pvtu`` with a piece ``<stem>_NNNN_R.vtu`` per rank. Collective methods.

    Args:
        folder: the output folder.
        stem: the series' name ("deformed", "surface").
        comm: the ranks writing pieces; rank 0 writes the index and the summaries.
    """

    def __init__(self, folder, stem, comm):
        self.folder, self.stem, self.comm = os.fspath(folder), stem, comm
        self.index = PvdIndex(os.path.join(self.folder, f"{stem}.pvd"))
        self.started, self.template = False, None
        self.writer = None  # the GridWriter, from the first frame
        # rank 0: frames dropped from the index, not yet written again ({file: its pieces}),
        # and pieces of rewritten frames that the new frame does not have
        self.stale, self.orphans = {}, set()

    def _start(self, keep):
        """Keep the frames of an existing index for which ``keep(time)`` and rewrite the index
        (rank 0); the others' files are overwritten by the frames of the same name or deleted
        at :meth:`close` (unlinking a file cost 3 ms here, 20 times a frame's writing). The
        ranks wait for each other before (every piece of the frames to drop is written) and
        after."""
        self.comm.barrier()
        if self.comm.rank == 0:
            kept = []
            for t, f in self.index.read():
                if keep(t):
                    kept.append((t, f))
                else:
                    self.stale[f] = _pieces(os.path.join(self.folder, f))
            self.index.create(kept)
        self.comm.barrier()
        self.started = True

    def resume(self, t_max, inclusive=True):
        """Keep the frames up to ``t_max`` (relative tolerance 1e-12) of an earlier run; the
        one at ``t_max`` too if ``inclusive``."""
        self._start(kept_until(t_max, inclusive))

    def write(self, step, time, grid):
        """Frame number ``step`` at ``time``: this rank's piece ``grid``; on a first frame the
        index of an earlier run is started afresh (its files: see :meth:`_start`)."""
        if not self.started:
            self._start(lambda t: False)
        if self.writer is None:
            self.writer = GridWriter()
        name = f"{self.stem}_{step:04d}"
        if self.comm.size == 1:
            file = f"{name}.vtu"
            self.writer.write(os.path.join(self.folder, file), grid)
        else:
            file = f"{name}.pvtu"
            self.writer.write(os.path.join(self.folder, f"{name}_{self.comm.rank}.vtu"), grid)
            if self.comm.rank == 0:
                if self.template is None:
                    self.template = summary_template(grid, self.comm.size, self.folder)
                write_summary(os.path.join(self.folder, file), self.template)
        if self.comm.rank == 0:
            self._rewritten(file, name)
            self.index.append(time, file)

    def _rewritten(self, file, name):
        """Frame ``file`` is written again: no longer stale; of its old pieces, those the new
        frame does not have (an earlier run on more ranks) are orphans."""
        old = self.stale.pop(file, None)
        if old:
            new = {os.path.join(self.folder, f"{name}_{r}.vtu") for r in range(self.comm.size)}
            self.orphans.update(set(old) - new)

    def close(self):
        """Close the index (rank 0 keeps it open between frames) and delete the files of the
        dropped frames that were not written again (rank 0). Collective."""
        self.index.close()
        if self.comm.rank == 0:
            files = list(self.orphans)
            for f, pieces in self.stale.items():
                files += [os.path.join(self.folder, f), *pieces]
            for f in files:
                if os.path.exists(f):
                    os.remove(f)
            self.stale, self.orphans = {}, set()


def _pieces(path):
    """The piece files of a ``.pvtu`` frame (none for a ``.vtu``, or if it cannot be read)."""
    if not (path.endswith(".pvtu") and os.path.exists(path)):
        return []
    from xml.etree.ElementTree import ParseError

    try:
        return piece_names(path)
    except ParseError:
        return []


def _line(time, file):
    return f'<DataSet timestep="{float(time)!r}" group="" part="0" file="{_escape(file)}"/>\n'


def _escape(text):
    """``text`` for a double-quoted XML attribute (what ``xml.sax.saxutils.quoteattr`` does
    without its choice of quotes; that module imports urllib, http and ssl: 10 ms a start)."""
    for a, b in (("&", "&amp;"), ("<", "&lt;"), (">", "&gt;"), ('"', "&quot;")):
        text = text.replace(a, b)
    return text.replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#9;")


__all__ = ["PvdIndex", "VtkSeries", "piece_names"]
