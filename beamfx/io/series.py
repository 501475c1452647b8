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
        import xml.etree.ElementTree as ET

        if not os.path.exists(self.path):
            return []
        root = ET.parse(self.path).getroot()
        return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


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

    def _start(self, keep):
        """Keep the frames of an existing index for which ``keep(time)``, delete the files of
        the others and rewrite the index (rank 0). The ranks wait for each other before (every
        piece of the frames to drop is written) and after (no new piece is written before an
        old one of the same name is removed)."""
        self.comm.barrier()
        if self.comm.rank == 0:
            kept = []
            for t, f in self.index.read():
                if keep(t):
                    kept.append((t, f))
                else:
                    _remove_frame(os.path.join(self.folder, f))
            self.index.create(kept)
        self.comm.barrier()
        self.started = True

    def resume(self, t_max):
        """Keep the frames up to ``t_max`` (relative tolerance 1e-12) of an earlier run."""
        self._start(lambda t: t <= t_max * (1 + 1e-12) + 1e-300)

    def write(self, step, time, grid):
        """Frame number ``step`` at ``time``: this rank's piece ``grid``; on a first frame the
        files of an earlier run's index are removed."""
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
            self.index.append(time, file)

    def close(self):
        """Close the index (rank 0 keeps it open between frames)."""
        self.index.close()


def _remove_frame(path):
    """Delete a frame file (a ``.pvtu`` with its pieces); missing files are fine."""
    files = [path]
    if path.endswith(".pvtu") and os.path.exists(path):
        from xml.etree.ElementTree import ParseError

        try:
            files += piece_names(path)
        except ParseError:
            pass
    for f in files:
        if os.path.exists(f):
            os.remove(f)


def _line(time, file):
    return f'<DataSet timestep="{float(time)!r}" group="" part="0" file="{_escape(file)}"/>\n'


def _escape(text):
    """``text`` for a double-quoted XML attribute (what ``xml.sax.saxutils.quoteattr`` does
    without its choice of quotes; that module imports urllib, http and ssl: 10 ms a start)."""
    for a, b in (("&", "&amp;"), ("<", "&lt;"), (">", "&gt;"), ('"', "&quot;")):
        text = text.replace(a, b)
    return text.replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#9;")


__all__ = ["PvdIndex", "VtkSeries", "piece_names"]
