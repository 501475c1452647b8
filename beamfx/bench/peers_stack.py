"""The stack's fixed costs in one beamfx run, each measured alone: what a whole run of a small
model cannot go below while it builds a DOLFINx model and writes VTK frames.

For the peers report's why-line (:func:`.peers_report.whole_split_text`) where beamfx is
behind on whole runs: the run's own split says where its time went; these say how much of
each part is the stack's floor. Each part is timed in this warm process (forms and
expressions already loaded once, as in the second of the bench's two runs), as the median of
``repeats``, on the model of the bench setting:

* ``mesh``: ``dolfinx.mesh.create_mesh`` of the setting's cells and nodes (no beamfx code);
* ``space``: one ``FunctionSpace`` on that mesh (P1 scalar; the condensed roll-up makes 5:
  its unknown, the displacement and three DG0 section fields);
* ``forms``: the residual and tangent of a freshly built model from the JIT cache
  (``dolfinx.fem.form``: UFL signature, cache look-up, DOLFINx form);
* ``expression``: the section expression of the probes and frames from the cache (its UFL
  built, then as for the forms);
* ``frame``: one frame of the output the scene asks for, after the first (the centre line
  and the reactions: two .vtu files and their .pvd indices, through
  :class:`~beamfx.io.output.FrameWriter`).
"""

import gc
import statistics
import tempfile
import time


def _median(make, repeats):
    """Median seconds of ``make()()``: ``make`` prepares (untimed), its result is timed."""
    seconds = []
    for _ in range(repeats):
        timed = make()
        gc.disable()  # the garbage of the earlier repeats' models not collected in the timing
        try:
            t0 = time.perf_counter()
            timed()
            seconds.append(time.perf_counter() - t0)
        finally:
            gc.enable()
    return statistics.median(seconds)


def stack_costs(case, setting, repeats=7):
    """{part: seconds} of the module doc for ``setting`` ((elements, degree)) of ``case``, a
    P1 setting of one beam (its mesh rebuilt from its cells) run on one process."""
    import numpy as np
    import ufl
    from dolfinx import fem, mesh
    from dolfinx.cpp.graph import AdjacencyList_int64
    from dolfinx.mesh import GhostMode
    from mpi4py import MPI

    from ..analyses.planar_condensed import build_model
    from ..geometry.mesh import _serial_partitioner as one_part
    from ..io._sections import cell_nodes, section_evaluator
    from ..io.output import FrameWriter, OutputSettings
    from ..solvers.forms import compile_form
    from .scenes import case_scene

    scene = case_scene(case, *setting[:2])
    comm = MPI.COMM_WORLD
    points = list(scene.probes.values())

    def model():
        return build_model(scene.model, comm, points, scene.condense)

    m = model().mesh.mesh
    x, domain = m.geometry.x, m.ufl_domain()
    cells = AdjacencyList_int64(m.geometry.dofmap.array.reshape(len(x) - 1, -1).astype(np.int64))
    element = ufl.FiniteElement("Lagrange", m.ufl_cell(), 1)

    def new_mesh():  # as beamfx builds it in serial (geometry.mesh.build_mesh)
        return mesh.create_mesh(comm, cells, x, domain, GhostMode.shared_facet, one_part)

    def forms():
        built = model()
        return lambda: (compile_form(built.F), compile_form(built.J))

    def expression():
        built = model()
        return lambda: section_evaluator(built, cell_nodes(built.degree))

    reactions = {"at": {"force": [0.0] * 3, "moment": [0.0] * 3, "position": [0.0] * 3}}
    with tempfile.TemporaryDirectory(prefix="beamfx-stack-") as folder:

        def frame():  # a frame after the first (which also starts the series' files)
            built = model()
            writer = FrameWriter(folder, built, OutputSettings(dir=folder), scene.model.beams)
            writer.write(1, 1.0, reactions)
            return lambda: writer.write(2, 2.0, reactions)

        return {
            "mesh": _median(lambda: new_mesh, repeats),
            "space": _median(lambda: lambda: fem.FunctionSpace(m, element), repeats),
            "forms": _median(forms, repeats),
            "expression": _median(expression, repeats),
            "frame": _median(frame, repeats),
        }
