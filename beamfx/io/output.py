"""The ParaView frames of a run: what to write and when (``[output]``), and the writer.

:class:`OutputSettings` is the scene's ``[output]`` table (its fields are the keys).
:class:`FrameWriter` writes a frame of the current state when asked; :meth:`FrameWriter.want`
is the every/times policy. Each frame costs the same whatever the number of frames before it:
data files are written by VTK, one piece per rank of the cells it owns (nothing is gathered
to rank 0), and the time-series indices grow by one line (:mod:`beamfx.io.vtkfiles`,
:mod:`beamfx.io.series`).

Formats:

* ``vtu`` (default): ``deformed.pvd`` of the centre line, each element a VTK Lagrange curve
  through its k + 1 nodes (ParaView draws the computed curve), points at the deformed
  position, point arrays ``fields``, cell arrays ``cell`` (input index) and ``beam``;
* ``surface`` (default): ``surface.pvd``, the real section swept along the deformed centre
  line (:mod:`beamfx.io.surface`), for beams whose section has a shape;
* ``reactions`` (default): ``reactions.pvd``, one vertex per support (and spring to ground)
  at its current position with point arrays ``force`` and ``moment`` (global axes, the moment
  about the point), at the frames of the other series that have reactions (static, linear
  static, arc length; a transient's output steps, not its initial state); written by rank 0
  alone (the reactions are reduced already); none for a scene without supports;
* ``xdmf``: ``deformed.xdmf`` + ``.h5`` through DOLFINx (:mod:`beamfx.io.xdmf`): not a default,
  since DOLFINx rewrites its XML at every frame (the cost grows with the frames).

This module imports neither DOLFINx nor VTK (the scene reader uses the settings).
"""

import os
from dataclasses import dataclass

import numpy as np

from ..settings import option
from .fields import POINT_ARRAYS

FORMATS = ("vtu", "surface", "reactions", "xdmf")
VTK_FORMATS = ("vtu", "surface", "reactions")
TRANSIENT_FRAMES = 100  # frames of a transient run when ``every`` is not given (issue 15:
# output under 10 % of a run; 200 frames were 11 % of the spin-up demo by themselves)
SCRIPT = "open_in_paraview.py"


@dataclass(frozen=True)
class OutputSettings:
    """What ``[output]`` says (see docs/scenes.md)."""

    dir: str = option("results", doc="output folder (`beamfx run --out` overrides it)")
    every: int | None = option(
        None,
        positive=True,
        doc="a frame every this many accepted steps (load, arc-length or time steps); "
        "default: every step, a transient about 100 frames",
    )
    times: tuple[float, ...] | None = option(
        None,
        doc="frames at the first accepted step at or past each of these times (load "
        "factors), instead of `every`",
    )
    fields: tuple[str, ...] = option(
        POINT_ARRAYS, choices=POINT_ARRAYS, doc="point arrays written in the frames"
    )
    reaction_rows: str = option(
        "frames",
        choices=("frames", "steps"),
        doc="rows of a transient's reactions.csv: at the frame steps (and the last), or at "
        "every time step (`steps`: two vector assemblies more per step); the ParaView "
        "reactions stay at the frames",
    )
    formats: tuple[str, ...] = option(
        VTK_FORMATS,
        choices=FORMATS,
        doc="files written: `vtu` (centre line), `surface` (swept section), `reactions` "
        "(the supports' forces and moments, where there are supports), `xdmf` (HDF5; its "
        "cost grows with the frames)",
    )

    def problems(self):
        """(key, message) of contradictions between the keys."""
        if self.every is not None and self.times is not None:
            yield "times", "give either every or times, not both"
        if self.times is not None and list(self.times) != sorted(self.times):
            yield "times", f"must be increasing, got {list(self.times)}"
        for key in ("fields", "formats"):
            values = getattr(self, key)
            if len(set(values)) != len(values):
                yield key, f"lists a value twice: {list(values)}"


def default_every(analysis, steps=None):
    """``every`` when not given: 1 for static, arc-length and the others, and for a transient
    of ``steps`` time steps about :data:`TRANSIENT_FRAMES` frames."""
    if analysis == "transient" and steps:
        return max(1, round(steps / TRANSIENT_FRAMES))
    return 1


def prepare_output(settings):
    """Check before the solve that the output can be written: VTK is importable (and is
    imported now, before DOLFINx, see :func:`beamfx.io.vtkfiles.import_vtk`).

    Raises:
        beamfx.io.vtkfiles.OutputUnavailable: (an OSError) if a VTK format is asked for and
            VTK is missing.
    """
    if set(settings.formats) & set(VTK_FORMATS):
        from .vtkfiles import import_vtk

        import_vtk()


class FramePolicy:
    """Which accepted steps are frames: with ``times`` the first step at or past each time,
    else every ``every``-th step; the last step of a run always, and no step twice."""

    def __init__(self, settings):
        self.times, self.every = settings.times or (), settings.every or 1
        self.by_time = settings.times is not None
        self.last_step, self.next_time = None, 0

    def want(self, step, time, last=False):
        """Is accepted step ``step`` at ``time`` (the ``last`` one of the run?) a frame?"""
        if step == self.last_step:
            return False
        if last:
            return True
        if self.by_time:
            return self.next_time < len(self.times) and _reached(time, self.times[self.next_time])
        return step % self.every == 0

    def record(self, step, time):
        """Step ``step`` at ``time`` was written: the times it reached are done."""
        self.last_step = step
        while self.next_time < len(self.times) and _reached(time, self.times[self.next_time]):
            self.next_time += 1

    def resume(self, t_max):
        """A run restarted at ``t_max``: the times up to it are done."""
        self.last_step = None
        self.next_time = sum(1 for t in self.times if _reached(t_max, t))


class FrameWriter:
    """The frames of one run. Collective: every rank calls every method.

    Args:
        folder: the output folder (it exists).
        model: :class:`~beamfx.analyses.model.BeamModel` whose current state is written.
        settings: :class:`OutputSettings`.
        beams: the scene's beams (``scene.model.beams``), for the section outlines.
        comm: the model's communicator (default ``model.comm``).
    """

    def __init__(self, folder, model, settings, beams, comm=None):
        from .surface import model_outlines

        self.folder, self.model, self.settings = os.fspath(folder), model, settings
        self.comm = comm or model.comm
        self.names = [b.name for b in beams]
        self.outlines = model_outlines(beams)
        self.series, self.xdmf, self._ends, self._swept = {}, None, None, None
        prepare_output(settings)
        if set(settings.formats) & set(VTK_FORMATS):
            from .series import VtkSeries
            from .vtkfiles import GridBuffer

            if "vtu" in settings.formats:
                self.series["deformed"] = VtkSeries(self.folder, "deformed", self.comm)
            if "surface" in settings.formats and any(v is not None for v in self.outlines.values()):
                self.series["surface"] = VtkSeries(self.folder, "surface", self.comm)
            self.grids = {name: GridBuffer() for name in (*self.series, "reactions")}
        if "xdmf" in settings.formats:
            from .xdmf import XdmfSeries

            path = os.path.join(self.folder, "deformed.xdmf")
            self.xdmf = XdmfSeries(path, model.degree, settings.fields, self.comm)
        spec = getattr(model, "spec", None)
        points = spec is not None and bool(spec.supports or spec.springs)
        self.has_reactions = "reactions" in settings.formats and points
        self.reactions = None  # rank 0: the series of the reactions
        self.reaction_frames = 0  # frames of it written (counted on every rank)
        if self.has_reactions and self.comm.rank == 0:
            from mpi4py import MPI

            from .series import VtkSeries

            self.reactions = VtkSeries(self.folder, "reactions", MPI.COMM_SELF)
        if "deformed" in self.series:
            write_paraview_script(self.folder, self.comm)
        self.policy = FramePolicy(settings)

    def want(self, step, time, last=False):
        """Whether accepted step ``step`` at ``time`` is a frame (:class:`FramePolicy`)."""
        return self.policy.want(step, time, last)

    @property
    def reads_sections(self):
        """Whether a frame evaluates the section quantities of all owned cells (the centre
        line, the surface or XDMF is written): the other output of its step can share them
        (:func:`~beamfx.io.fields.shared_fields`)."""
        return bool(self.series) or self.xdmf is not None

    def follow(self, model):
        """Write the state of ``model`` from now on: another formulation on the same mesh
        (the full model a condensed one fell back to); the series go on."""
        self.model = model

    def write(self, step, time, reactions=None):
        """Write the current state as frame ``step`` at ``time`` (each rank its own piece),
        and ``reactions`` ({point: {force, moment, position}}, the same on every rank) if
        given (rank 0)."""
        from .fields import local_fields
        from .vtkfiles import lagrange_line_grid

        if self.has_reactions and reactions:
            self.reaction_frames += 1
            if self.reactions is not None:
                from .reaction_files import reaction_grid

                grid = reaction_grid(reactions, self.grids["reactions"])
                self.reactions.write(step, time, grid)
        if not self.series and self.xdmf is None:  # formats = []: nothing to write
            self.policy.record(step, time)
            return
        fields = local_fields(self.model)
        arrays = self.settings.fields
        cell_data = {"cell": fields["cell"], "beam": fields["beam"]}
        if "deformed" in self.series:
            point_data = {name: fields[name] for name in arrays}
            points = fields["X"] + fields["u"]
            grid = lagrange_line_grid(
                points, self.model.degree, point_data, cell_data, self.grids["deformed"]
            )
            self.series["deformed"].write(step, time, grid)
        if "surface" in self.series:
            self.series["surface"].write(step, time, self._surface(fields, arrays))
        if self.xdmf is not None:
            self.xdmf.write(time, fields)
        self.policy.record(step, time)

    def _surface(self, fields, arrays):
        from .surface import SweptSurface, surface_grid

        if self._ends is None:  # first and last input cell of every beam, over all ranks
            from mpi4py import MPI

            first = np.full(len(self.names), np.iinfo(np.int64).max, dtype=np.int64)
            last = np.full(len(self.names), -1, dtype=np.int64)
            np.minimum.at(first, fields["beam"], fields["cell"])
            np.maximum.at(last, fields["beam"], fields["cell"])
            # element-wise over ranks (the object allreduce compares whole arrays)
            ends = (np.empty_like(first), np.empty_like(last))
            self.comm.Allreduce(first, ends[0], MPI.MIN)
            self.comm.Allreduce(last, ends[1], MPI.MAX)
            self._ends = ends
        if self._swept is None or self._swept.degree != self.model.degree:
            # the cells made once, the points at every frame (surface 0.53 -> 0.32 ms a frame)
            self._swept = SweptSurface(
                self.model.degree, self.names, self.outlines, ends=self._ends
            )
        return surface_grid(self._swept(fields), arrays, self.grids["surface"])

    def resume(self, t_max, step=None):
        """Keep the frames up to ``t_max`` of an earlier run in the folder (a restart) and
        drop later ones with their files. ``step``: the step at ``t_max`` (a checkpoint's);
        its frame, written where the earlier run stopped, is dropped too unless ``every``
        asks for that step, so that the series goes on as an uninterrupted run's. Returns a
        note for the log (XDMF: :meth:`~beamfx.io.xdmf.XdmfSeries.resume`), or None."""
        policy = self.policy
        inclusive = step is None or policy.by_time or step % policy.every == 0
        for series in self._all_series():
            series.resume(t_max, inclusive)
        note = self.xdmf.resume(t_max, inclusive) if self.xdmf is not None else None
        self.policy.resume(t_max)
        return note

    def close(self):
        """Close the files that stay open (the series' indices, XDMF)."""
        for series in self._all_series():
            series.close()
        if self.xdmf is not None:
            self.xdmf.close()

    def _all_series(self):
        """The VTK series this rank writes (the reactions' on rank 0 only)."""
        return [*self.series.values(), *([self.reactions] if self.reactions else [])]

    def files(self):
        """The ``paraview`` entry of results.json: the series written and the script."""
        out = {}
        if "deformed" in self.series:
            out["pvd"] = "deformed.pvd"
        if self.xdmf is not None:
            out["xdmf"] = "deformed.xdmf"
        if "surface" in self.series:
            out["surface"] = "surface.pvd"
        if self.reaction_frames:
            out["reactions"] = "reactions.pvd"
        if "deformed" in self.series:
            out["script"] = SCRIPT
        return out


def _reached(time, target):
    return time >= target - 1e-9 * max(1.0, abs(target))


def write_paraview_script(folder, comm):
    """Copy ``open_in_paraview.py`` (a pvpython script showing the results) into ``folder``
    (rank 0), with that folder's absolute path as the fallback for ``paraview --script``."""
    if comm.rank != 0:
        return
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "pvscripts", SCRIPT), encoding="utf-8") as f:
        text = f.read()
    folder = os.path.abspath(os.fspath(folder))
    text = text.replace("\nWRITTEN_TO = None\n", f"\nWRITTEN_TO = {folder!r}\n", 1)
    target = os.path.join(folder, SCRIPT)
    tmp = f"{target}.tmp{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, target)


__all__ = ["FramePolicy", "FrameWriter", "OutputSettings", "default_every", "prepare_output"]
