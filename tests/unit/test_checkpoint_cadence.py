"""When a transient writes its periodic checkpoints (:func:`beamfx.analyses.transient.checkpoint_due`):
exactly every ``checkpoint_every`` steps when the scene gives it, by default every 50 steps
once 10 s of wall time have passed since the last one."""

import time

from mpi4py import MPI

from beamfx.analyses.transient import CHECKPOINT_SECONDS, CHECKPOINT_STEPS, checkpoint_due

SELF = MPI.COMM_SELF


def test_a_given_interval_is_kept_exactly_whatever_the_clock():
    now = [time.perf_counter()]  # just saved
    assert [s for s in range(1, 13) if checkpoint_due(4, s, now, SELF)] == [4, 8, 12]
    assert not any(checkpoint_due(0, s, now, SELF) for s in range(1, 200))


def test_the_default_waits_for_the_wall_time_then_keeps_the_step_interval():
    recent = [time.perf_counter()]
    old = [time.perf_counter() - CHECKPOINT_SECONDS - 1.0]
    steps = range(1, 4 * CHECKPOINT_STEPS + 1)
    assert not any(checkpoint_due(None, s, recent, SELF) for s in steps)
    due = [s for s in steps if checkpoint_due(None, s, old, SELF)]
    assert due == [CHECKPOINT_STEPS * k for k in (1, 2, 3, 4)]
