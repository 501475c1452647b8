"""XDMF 3 output through DOLFINx's ``XDMFFile`` (HDF5, collective, parallel): not a default.

DOLFINx 0.5.2 rewrites the whole XML part of the file at every ``write_function`` (measured:
5 ms a frame of 7 arrays at 100 frames, 51 ms at 1 000, 210 ms at 2 000: the cost grows with
the frames written), and its XDMF writer knows no line cells above degree 2 ("Could not find
VTK string for cell order" for P3 and P4). So the series is a polyline: every element drawn as
k straight segments through its k + 1 nodes (the points of :func:`~beamfx.io.fields.local_fields`,
duplicated between elements), on an output mesh whose cells stay on the rank that owns the
element, so nothing is gathered. The mesh is the reference centre line ``X`` (written once);
``u`` and the other arrays are point functions per time: warp by ``u`` for the deformed shape.

A restart (:meth:`XdmfSeries.resume`) keeps the earlier run's frames up to the checkpoint,
as the ``.pvd`` series does: the XML is cut back to them (rank 0) and DOLFINx's ``XDMFFile``
appends to it (mode ``"a"``, tested on 0.5.2: the new grids join each array's temporal
collection and refer to the mesh written first). HDF5 refuses to create a data set that
exists, and frames written after the checkpoint (a killed run) left theirs in the ``.h5``
under the very names the restarted frames take (``/Function/u/<time>``); then that file is
renamed ``<stem>.part<k>.h5``, the kept grids point at it, and the new frames go into a new
``<stem>.h5`` (the ``.xdmf`` reads both; keep them together). An earlier file that cannot
be read is set aside as ``<stem>.before_restart.xdmf`` (and ``.h5``) and the series starts
afresh, saying so.
"""

import os
import re
import xml.etree.ElementTree as ET

import numpy as np

from .series import kept_until

XINCLUDE = "http://www.w3.org/2001/XInclude"


def _keep_local(comm, nparts, tdim, cells, ghost_mode):
    """Cell partitioner of the output mesh: every cell stays on the rank that passed it."""
    from dolfinx.cpp.graph import AdjacencyList_int32

    return AdjacencyList_int32(np.full(cells.num_nodes, comm.rank, dtype=np.int32))


def polyline_mesh(comm, points, degree):
    """P1 interval mesh of the elements' nodes (``degree`` + 1 per element, consecutive), each
    element k segments, cells kept on their rank. Returns the vector P1 space on it and the
    (block) dof of each local point."""
    import dolfinx.fem
    import dolfinx.mesh
    import ufl

    k, n = degree, len(points)
    offset = comm.exscan(n) or 0
    first = (k + 1) * np.arange(n // (k + 1))[:, None] + np.arange(k)[None, :]
    cells = offset + np.stack([first.ravel(), first.ravel() + 1], axis=1).astype(np.int64)
    cell = ufl.Cell("interval", geometric_dimension=3)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", cell, 1, variant="equispaced"))
    mesh = dolfinx.mesh.create_mesh(comm, cells, points, domain, partitioner=_keep_local)
    V = dolfinx.fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=3)
    nodes = mesh.geometry.dofmap.array.reshape(-1, 2)
    dofs = V.dofmap.list.array.reshape(-1, 2)  # P1: local dof i sits at the cell's vertex i
    dof_of_node = np.empty(len(mesh.geometry.x), dtype=np.int64)
    dof_of_node[nodes.ravel()] = dofs.ravel()
    dof_of_point = np.empty(n, dtype=np.int64)
    dof_of_point[np.asarray(mesh.geometry.input_global_indices) - offset] = dof_of_node
    return V, dof_of_point


class XdmfSeries:
    """``<stem>.xdmf`` and ``<stem>.h5``: the point arrays of every frame (collective).

    Args:
        path: the ``.xdmf`` file (replaced at the first frame; continued after :meth:`resume`).
        degree: the element degree k.
        arrays: names of the (n, 3) point arrays to write.
        comm: the communicator of the model.
    """

    def __init__(self, path, degree, arrays, comm):
        self.path, self.degree, self.arrays, self.comm = os.fspath(path), degree, arrays, comm
        self.file, self.mode = None, "w"

    def _open(self, fields):
        import dolfinx.fem
        import dolfinx.io

        V, self.dof = polyline_mesh(self.comm, fields["X"], self.degree)
        self.functions = {name: dolfinx.fem.Function(V, name=name) for name in self.arrays}
        self.file = dolfinx.io.XDMFFile(self.comm, self.path, self.mode)
        if self.mode == "w":  # appended: the earlier run's mesh (the same) is referred to
            self.file.write_mesh(V.mesh)

    def write(self, time, fields):
        """One frame of the :func:`~beamfx.io.fields.local_fields` ``fields`` at ``time``."""
        if self.file is None:
            self._open(fields)
        for name, f in self.functions.items():
            f.x.array.reshape(-1, 3)[self.dof] = fields[name]
            self.file.write_function(f, float(time))

    def resume(self, t_max, inclusive=True):
        """Keep the earlier run's frames up to ``t_max`` (relative tolerance 1e-12; the one at
        ``t_max`` too if ``inclusive``) and append the next ones (see the module docstring).
        Collective; returns a note for the log, or None."""
        self.close()
        out = _resume_file(self.path, t_max, inclusive) if self.comm.rank == 0 else None
        self.mode, note = self.comm.bcast(out) if self.comm.size > 1 else out
        return note

    def close(self):
        """Close the file (again: nothing)."""
        if self.file is not None:
            self.file.close()
            self.file = None


def _resume_file(path, t_max, inclusive):
    """(mode of the restart's XDMFFile, note or None) after the earlier ``path`` is cut back
    to the frames up to ``t_max`` (rank 0: see the module docstring)."""
    stem = path.removesuffix(".xdmf")
    h5 = stem + ".h5"
    if not os.path.exists(path):
        return "w", None
    try:
        ET.register_namespace("xi", XINCLUDE)
        tree = ET.parse(path)
        frames = _frames(tree)
        if not os.path.exists(h5):
            raise OSError(f"{os.path.basename(h5)} is missing")
    except (ET.ParseError, OSError, ValueError, AttributeError) as e:
        return "w", _set_aside(path, stem, h5, e)
    keep = kept_until(t_max, inclusive)
    if not any(keep(t) for _, _, t in frames):  # nothing to keep: replaced at the first frame
        return "w", None  # (the condensed model's frames when the full one takes over)
    for parent, grid, t in frames:
        if not keep(t):
            parent.remove(grid)
    note = None
    after = kept_until(t_max)  # (the frames after the checkpoint)
    if any(not after(t) for _, _, t in frames):  # their data sets hold the restart's names
        part = _free_part(stem)
        _point_at(tree, os.path.basename(h5), os.path.basename(part))
        os.replace(h5, part)
        note = (
            f"XDMF: the frames after the checkpoint left their data in {os.path.basename(h5)}, "
            f"where the restart's frames of those times cannot be written: it is now "
            f"{os.path.basename(part)}, read by {os.path.basename(path)} for the frames up to "
            f"t = {t_max:.6g} (keep it beside it)"
        )
    _write(tree, path)
    return "a", note


def _frames(tree):
    """(collection, grid, time) of every frame of the temporal collections of ``tree``."""
    out = []
    for collection in tree.getroot().iter("Grid"):
        if collection.get("GridType") != "Collection":
            continue
        for grid in collection.findall("Grid"):
            out.append((collection, grid, float(grid.find("Time").get("Value"))))
    return out


def _free_part(stem):
    """``<stem>.part<k>.h5`` with the first k not in use."""
    k = 1
    while os.path.exists(f"{stem}.part{k}.h5"):
        k += 1
    return f"{stem}.part{k}.h5"


def _point_at(tree, old, new):
    """Let every data item of the file ``old`` (``old:/path``) read the file ``new``."""
    for item in tree.getroot().iter("DataItem"):
        if item.text and item.text.strip().startswith(f"{old}:"):
            item.text = new + item.text.strip()[len(old) :]


def _write(tree, path):
    """Write ``tree`` over ``path`` (atomically), declaring the XInclude prefix that
    DOLFINx's appended grids use even if no kept grid uses it."""
    text = ET.tostring(tree.getroot(), encoding="unicode")
    if f'xmlns:xi="{XINCLUDE}"' not in text:
        text = re.sub(r"^<Xdmf\b", f'<Xdmf xmlns:xi="{XINCLUDE}"', text, count=1)
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write('<?xml version="1.0"?>\n' + text + "\n")
    os.replace(tmp, path)


def _set_aside(path, stem, h5, error):
    """Rename an earlier XDMF series that cannot be read or appended to; the note."""
    names = []
    for old, ext in ((path, "xdmf"), (h5, "h5")):
        if os.path.exists(old):
            os.replace(old, f"{stem}.before_restart.{ext}")
            names.append(os.path.basename(f"{stem}.before_restart.{ext}"))
    return (
        f"XDMF: the earlier {os.path.basename(path)} cannot be continued ({error}): kept as "
        f"{' and '.join(names)}; the XDMF series starts afresh at the restart (its frames "
        "before it are in the .pvd series)"
    )
