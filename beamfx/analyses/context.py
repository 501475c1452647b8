"""What an analysis needs from the run besides its model and settings: where to write, what
to report, how to solve. One :class:`RunContext` per ``beamfx run``."""

import time
from collections.abc import Callable
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class RunContext:
    """The run side of an analysis: output folder, frames, probes, log and solver options.

    Attributes:
        analysis: the analysis type being run.
        model: the model in use (replaced by :meth:`fallback`).
        folder: the output folder (exists, writable).
        comm: the communicator of the run.
        log: message sink (rank 0 prints).
        frames: the ParaView series: ``want(step, time, last)``, ``write(step, time)``,
            ``resume(t_max)``, ``files()``.
        probes: ``{probe name: point name}`` of the scene.
        spec: the model description (:class:`~beamfx.spec.Model`).
        file: the scene file, for messages.
        solver_options: the scene's ``[solver]`` PETSc options.
        restart: a transient goes on from its last checkpoint in ``folder``.
        rebuild: ``rebuild() -> model``, the full (not condensed) model of the scene, for an
            analysis that falls back to it; None where there is nothing to fall back to.
    """

    analysis: str
    model: object
    folder: Path
    comm: object
    log: Callable
    frames: object
    probes: dict
    spec: object
    file: str = "<scene>"
    solver_options: dict = field(default_factory=dict)
    restart: bool = False
    rebuild: Callable | None = None
    latest: dict | None = None  # probe values of the last accepted state, tracked
    _points: list | None = field(default=None, init=False, repr=False)  # the probes' points
    latest_reactions: dict | None = None  # results.json entries of the last reactions
    _reaction_csv: object = field(default=None, init=False, repr=False)  # reactions.csv
    #: wall time (s) of the per-step output of :meth:`step` and :meth:`last_frame` (and of a
    #: transient's steps, inside its own "total"): probes (the first evaluation loads the
    #: section expression; a transient's with probes.csv), reactions (with reactions.csv), frames
    seconds: dict = field(default_factory=lambda: dict.fromkeys(OUTPUT_PARTS, 0.0))

    def reactions(self, model):
        """Support reactions and their balance with the loads at the model's current state
        (collective), as results.json entries (:func:`beamfx.analyses.reactions.entries`);
        kept as :attr:`latest_reactions`."""
        from .reactions import entries

        self.latest_reactions = entries(model)
        return self.latest_reactions

    def probe_values(self, model, track=True, full=True):
        """Probe values of the model's current state (collective): ``{point: values}``, the
        rotations unwrapped along the path of earlier calls when ``track``; with ``full=False``
        only position, displacement and rotation (a history's columns, at every step: call
        it once more with ``full=True`` at the end, the final probes read :attr:`latest`)."""
        from ..io import evaluate_points, track_rotations

        if self._points is None:
            self._points = list(dict.fromkeys(self.probes.values()))
        values = evaluate_points(model, self._points, full=full)
        self.latest = track_rotations(self.latest if track else None, values)
        return self.latest

    def probe_blocks(self, model):
        """The per-step recorder of the probes' points for a transient's history
        (:class:`~beamfx.io.probe_blocks.ProbeBlocks`), tracking on from :attr:`latest`; each
        drained block's last values become :attr:`latest`. Collective."""
        from ..io.probe_blocks import ProbeBlocks

        def keep(values):
            self.latest = values

        points = list(dict.fromkeys(self.probes.values()))
        return ProbeBlocks(model, points, self.comm, self.latest, keep)

    def step(self, model, step, time):
        """After an accepted step (static, arc length): probes tracked, the reactions (a row
        of ``reactions.csv``), and a frame where the output asks (each timed in
        :attr:`seconds`); with a frame, all three read one evaluation of the sections."""
        t0 = _now()
        frame = self.frames.want(step, time)
        with self._sharing(model, frame):
            self.probe_values(model)
            t1 = _now()
            self.reaction_row(step, time, self.reactions(model))
            t2 = _now()
            if frame:
                self.frames.write(step, time, self.latest_reactions["reactions"])
        seconds = self.seconds
        seconds["probes"] += t1 - t0
        seconds["reactions"] += t2 - t1
        seconds["frames"] += _now() - t2

    def _sharing(self, model, frame):
        """The context of a step's output: where its frame evaluates the sections of all
        owned cells, the probes and reactions read that one evaluation
        (:func:`~beamfx.io.fields.shared_fields`; the same numbers)."""
        if frame and getattr(self.frames, "reads_sections", False):
            from ..io.fields import shared_fields

            return shared_fields(model)
        return nullcontext()

    def reaction_row(self, step, time, entry):
        """A row of ``reactions.csv`` (the transient's columns without the inertia; ``time``:
        the load factor), the file started at the first row (rank 0 writes). Collective."""
        from ..io.reaction_files import ReactionCsv, columns, static_row

        if self._reaction_csv is None:
            self._reaction_csv = ReactionCsv(self.folder / "reactions.csv", self.comm)
            self._reaction_csv.start(columns(list(entry["reactions"]), transient=False))
        self._reaction_csv.write(static_row(step, time, entry))

    def close(self):
        """Close the files the context keeps open (``reactions.csv``)."""
        if self._reaction_csv is not None:
            self._reaction_csv.close()
        self._reaction_csv = None

    def require_mass(self, model, analysis):
        """Raise (naming the scene) if the model has no mass: no density and no point mass."""
        import numpy as np
        from mpi4py import MPI

        inertia = model.discretisation.inertia.x.array
        mass = model.comm.allreduce(float(np.max(inertia, initial=0.0)), op=MPI.MAX)
        if mass <= 0 and not any(pm.mass or np.any(pm.inertia) for pm in self.spec.point_masses):
            raise ValueError(
                f"{self.file}: a {analysis} analysis needs mass: give [material] rho, or rho_A "
                "and rho_I of the general sections, or [[masses]]"
            )

    def last_frame(self, step, time, reactions=None):
        """The last step of a run always gets a frame (if ``every`` skipped it), with
        ``reactions`` ({point: {force, moment, position}}; default: the latest of
        :meth:`reactions`)."""
        if reactions is None and self.latest_reactions is not None:
            reactions = self.latest_reactions["reactions"]
        if self.frames.want(step, time, last=True):
            t0 = _now()
            self.frames.write(step, time, reactions)
            self.seconds["frames"] += _now() - t0

    def fallback(self):
        """The full model instead of the condensed one: the failed attempt's probes and frames
        are forgotten, and the new model is returned (and kept as :attr:`model`)."""
        self.latest = self.latest_reactions = None
        self.close()  # reactions.csv starts again at the new model's first step
        self.frames.resume(0.0)
        self.model, self.rebuild = self.rebuild(), None
        self.frames.follow(self.model)
        return self.model


#: the parts of :attr:`RunContext.seconds`
OUTPUT_PARTS = ("probes", "reactions", "frames")
_now = time.perf_counter


__all__ = ["OUTPUT_PARTS", "RunContext"]
