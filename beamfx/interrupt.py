"""SIGINT and SIGTERM during ``beamfx`` commands, and errors that must stop every MPI rank.

:func:`handle_signals` (installed by the command line only) turns SIGINT and SIGTERM into
:class:`Interrupted`, a ``KeyboardInterrupt`` that carries the signal, so the command ends
with a one-line message and exit status 128 + signal (130, 143) instead of a traceback.
Inside :func:`deferred` (a time march) the first signal only sets a flag that the march reads
between steps with :func:`pending`, so it can stop at an accepted step, write its checkpoint
and its results ("stopped", "interrupted by SIGINT"); a second signal stops at once.

:func:`stop_everywhere` ends a command that failed on some MPI ranks: the failed ranks agree
within a few seconds on a communicator of their own; if every rank failed, rank 0 prints the
messages once and all return; if some rank is still busy (waiting in a collective call that
will never complete), the failed rank prints its message and aborts the whole job.
"""

import signal
import sys
import time
from contextlib import contextmanager

SIGNALS = (signal.SIGINT, signal.SIGTERM)
AGREE_SECONDS = 5.0  # how long failed ranks wait for the others before aborting the job

_state = {"installed": False, "deferred": 0, "received": 0}


class Interrupted(KeyboardInterrupt):
    """The command was interrupted by ``signum``."""

    collective = True

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum

    def __str__(self):
        return reason(self.signum)

    @property
    def exit_code(self):
        """The exit status of a command ended by the signal: 128 + its number."""
        return 128 + self.signum


def interruption(error):
    """The :class:`Interrupted` that ``error`` is or was raised from (a signal that arrived in
    an import or a C callback comes back as another exception, e.g. ``ImportError:
    initialization failed``), or None."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, Interrupted):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def reason(signum):
    """``interrupted by SIGINT`` (the words of results.json)."""
    return f"interrupted by {signal.Signals(signum).name}"


def _handler(signum, frame):
    first = not _state["received"]
    _state["received"] = _state["received"] or signum
    if not (_state["deferred"] and first):
        raise Interrupted(signum)


@contextmanager
def handle_signals():
    """SIGINT and SIGTERM raise :class:`Interrupted` (or, in :func:`deferred`, set a flag)
    while the block runs; the previous handlers afterwards. A no-op off the main thread."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _handler) for s in SIGNALS}
    _state.update(installed=True, received=0)
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
        _state["installed"] = False


@contextmanager
def deferred():
    """Inside, a first signal is only recorded (read it with :func:`pending`)."""
    _state["deferred"] += 1
    try:
        yield
    finally:
        _state["deferred"] -= 1


def received():
    """The signal received since :func:`handle_signals` began, or 0."""
    return _state["received"]


def pending(comm=None):
    """The signal any rank received (0 if none). Collective when ``comm`` has several ranks:
    call it at the same point of the march on every rank."""
    signum = _state["received"]
    if comm is not None and comm.size > 1:
        from mpi4py import MPI

        signum = comm.allreduce(signum, op=MPI.MAX)
    return signum


def error_comm():
    """A duplicate of COMM_WORLD on which only failed ranks communicate (create it on every
    rank at the start of a command)."""
    from mpi4py import MPI

    return MPI.COMM_WORLD.Dup() if MPI.COMM_WORLD.size > 1 else None


def stop_everywhere(message, code, comm, wait=AGREE_SECONDS):
    """End a command that failed here with ``message``; returns ``code`` or aborts the job.

    Serial: print and return. Under MPI (``comm`` from :func:`error_comm`): wait up to
    ``wait`` seconds for every rank to fail too; then rank 0 prints the distinct messages and
    all return ``code``; else print this rank's message and ``MPI_Abort`` every rank.
    """
    if comm is None:
        print(message, file=sys.stderr, flush=True)
        return code
    request, deadline = comm.Ibarrier(), time.monotonic() + wait
    while not request.Test():
        if time.monotonic() > deadline:
            print(f"{message} (rank {comm.rank}; stopping all ranks)", file=sys.stderr, flush=True)
            comm.Abort(code)
        time.sleep(0.01)
    messages = comm.gather(message, root=0)
    if comm.rank == 0:
        print("\n".join(dict.fromkeys(messages)), file=sys.stderr, flush=True)
    return code


__all__ = [
    "Interrupted",
    "deferred",
    "error_comm",
    "handle_signals",
    "interruption",
    "pending",
    "reason",
    "received",
    "stop_everywhere",
]
