"""Rank-0 logging and a one-line progress display."""

import os
import sys
import time

from mpi4py import MPI


def log(msg, comm=MPI.COMM_WORLD, stream=None):
    """Print ``msg`` on rank 0 only, flushed (other ranks' output is block-buffered)."""
    if comm.rank == 0:  # one write per line, so lines of concurrent ensemble members stay whole
        print(f"{msg}\n", end="", file=stream or sys.stdout, flush=True)


class Progress:
    """Progress of a loop: one self-overwriting line on a terminal, plain lines otherwise.

    Silent on ranks other than 0. Use as a context manager, or call :meth:`close`.

    Args:
        total: number of units of work, or None if unknown.
        label: text before the counter.
        stream: output stream (standard output by default).
        comm: the communicator whose rank 0 prints.
    """

    def __init__(self, total=None, label="", stream=None, comm=MPI.COMM_WORLD, every=None):
        self.total, self.label = total, label
        self.stream = stream or sys.stdout
        self.active = comm.rank == 0
        # under mpirun a rank's output is a pseudo-terminal even when mpirun's goes to a file:
        # plain lines there (a redrawn line became one long line of carriage returns)
        launched = "OMPI_COMM_WORLD_SIZE" in os.environ or comm.size > 1
        self.tty = (
            self.active and not launched and hasattr(self.stream, "isatty") and self.stream.isatty()
        )
        self._width = 0
        # seconds between lines shown (None: every update); a terminal line is cheap to
        # overwrite, so it refreshes at least 5 times as often as plain lines are written
        self.every = every and (min(every, 0.2) if self.tty else every)
        self._last = None

    def due(self):
        """Whether :meth:`update` would show a line now (a caller may skip making its text)."""
        if not self.active:
            return False
        return not (
            self.every and self._last is not None and time.monotonic() - self._last < self.every
        )

    def update(self, done, text=""):
        """Report ``done`` units finished, with an optional note (e.g. "λ = 0.5, 4 its").

        With ``every`` set, updates closer than that many seconds to the last one shown are
        skipped (a time stepper may take thousands of steps); on a terminal at most 0.2 s."""
        if not self.active:
            return
        now = time.monotonic()
        if self.every and self._last is not None and now - self._last < self.every:
            return
        self._last = now
        count = f"{done}/{self.total}" if self.total else f"{done}"
        line = " ".join(p for p in (self.label, count, text) if p)
        if self.tty:
            pad = max(0, self._width - len(line))
            self.stream.write("\r" + line + " " * pad)
            self._width = len(line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self, text=""):
        """End the progress line (a newline on a terminal), with an optional final note."""
        if not self.active:
            return
        if self.tty and self._width:
            self.stream.write("\n")
            self._width = 0
        if text:
            self.stream.write(text + "\n")
        self.stream.flush()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
