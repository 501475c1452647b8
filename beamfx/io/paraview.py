"""ParaView files of the nodal fields: VTU (+ PVD time series) and XDMF 3 (data inline).

All writers take the arrays of :func:`beamfx.io.fields.nodal_fields` on rank 0 and do nothing
on the other ranks, so they can be called from every rank. Files are written to a temporary
name and renamed, so a reader (or a crash) never sees half a file, and the series files are
rewritten after every step: they are valid while the analysis runs.

Points are the deformed positions X + u; ``X`` is written too, so ParaView's "Warp By
Vector" is not needed. Every array of ``n_points`` rows is written as point data: (n, 3) as a
vector, (n,) as a scalar. ``cells`` holds the line segments.
"""

import os
import xml.etree.ElementTree as ET

import numpy as np
from mpi4py import MPI

VTK_LINE = 3


def _point_arrays(fields):
    n = len(fields["X"])
    return {k: np.asarray(v) for k, v in fields.items() if k != "cells" and len(v) == n}


def _text(a):
    """Numbers in round-trip precision, one point or cell per line."""
    a = np.asarray(a)
    rows = a.reshape(len(a), -1) if a.ndim > 1 else a.reshape(-1, 1)
    return "\n".join(" ".join(map(repr, r)) for r in rows.tolist())


def _write_atomic(path, root):
    """The XML tree ``root`` to ``path``, through a temporary file and a rename."""
    ET.indent(root, space=" ")
    text = '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    path = os.fspath(path)
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def _vtu_array(parent, name, a, vtk_type):
    a = np.asarray(a)
    e = ET.SubElement(parent, "DataArray", type=vtk_type, format="ascii")
    if name:
        e.set("Name", name)
    e.set("NumberOfComponents", str(1 if a.ndim == 1 else a.shape[1]))
    e.text = "\n" + _text(a) + "\n"
    return e


def write_unstructured_vtu(path, points, cells, types, point_data):
    """VTK XML UnstructuredGrid (ascii): ``cells`` a list of index arrays (any sizes) with VTK
    ``types``, ``point_data`` a dict of arrays (``u`` marked as the vectors)."""
    root = ET.Element(
        "VTKFile",
        type="UnstructuredGrid",
        version="1.0",
        byte_order="LittleEndian",
        header_type="UInt64",
    )
    piece = ET.SubElement(
        ET.SubElement(root, "UnstructuredGrid"),
        "Piece",
        NumberOfPoints=str(len(points)),
        NumberOfCells=str(len(cells)),
    )
    pd = ET.SubElement(piece, "PointData")
    if "u" in point_data:
        pd.set("Vectors", "u")
    for name, a in point_data.items():
        a = np.asarray(a)
        _vtu_array(pd, name, a, "Int64" if a.dtype.kind in "iu" else "Float64")
    _vtu_array(ET.SubElement(piece, "Points"), None, np.asarray(points), "Float64")
    c = ET.SubElement(piece, "Cells")
    conn = np.concatenate(cells) if len(cells) else np.zeros(0, np.int64)
    offsets = np.cumsum([len(x) for x in cells], dtype=np.int64)
    _vtu_array(c, "connectivity", conn.astype(np.int64), "Int64")
    _vtu_array(c, "offsets", offsets, "Int64")
    _vtu_array(c, "types", np.asarray(types, np.uint8), "UInt8")
    _write_atomic(path, root)


def write_vtu(path, fields, comm=MPI.COMM_WORLD):
    """VTK XML UnstructuredGrid (ascii) of the polyline, VTK_LINE cells; rank 0 writes.

    Args:
        path: file name (".vtu").
        fields: the dict of :func:`~beamfx.io.fields.nodal_fields` (ignored off rank 0).
        comm: the communicator whose rank 0 writes.
    """
    if comm.rank != 0:
        return
    cells = np.asarray(fields["cells"], dtype=np.int64)
    points = np.asarray(fields["X"]) + np.asarray(fields["u"])
    types = np.full(len(cells), VTK_LINE)
    write_unstructured_vtu(path, points, list(cells), types, _point_arrays(fields))


class _Series:
    """A file listing one entry per step, rewritten whole (atomically) on rank 0 after each."""

    def __init__(self, path, comm=MPI.COMM_WORLD):
        self.path, self.comm, self.entries = os.fspath(path), comm, []

    def _append(self, entry):
        self.entries.append(entry)
        _write_atomic(self.path, self._tree())

    def resume(self, t_max):
        """Keep the entries of an existing file up to time ``t_max`` (a restarted run)."""
        if self.comm.rank != 0 or not os.path.exists(self.path):
            return
        root = ET.parse(self.path).getroot()
        self.entries = [entry for t, entry in self._read(root) if t <= t_max]
        _write_atomic(self.path, self._tree())


class PvdSeries(_Series):
    """ParaView collection of .vtu files, one per time (or load factor), rewritten on each add.

    Args:
        path: the ".pvd" file; an existing one is replaced.
        comm: the communicator whose rank 0 writes.
    """

    def add(self, time, vtu_path):
        """Append a written ``vtu_path`` at ``time`` and rewrite the .pvd (rank 0)."""
        if self.comm.rank == 0:
            folder = os.path.dirname(os.path.abspath(self.path))
            self._append((float(time), os.path.relpath(os.fspath(vtu_path), folder)))

    @staticmethod
    def _read(root):
        return [
            (float(e.get("timestep")), (float(e.get("timestep")), e.get("file")))
            for e in root.iter("DataSet")
        ]

    def _tree(self):
        root = ET.Element("VTKFile", type="Collection", version="1.0", byte_order="LittleEndian")
        coll = ET.SubElement(root, "Collection")
        for t, f in self.entries:
            ET.SubElement(coll, "DataSet", timestep=repr(t), group="", part="0", file=f)
        return root


def _xdmf_item(parent, a, number_type):
    a = np.asarray(a)
    dims = " ".join(str(d) for d in a.shape)
    e = ET.SubElement(parent, "DataItem", Dimensions=dims, NumberType=number_type, Format="XML")
    e.set("Precision", "8")
    e.text = "\n" + _text(a) + "\n"
    return e


class XdmfSeries(_Series):
    """XDMF 3 temporal collection of the polyline with all data inline (``Format="XML"``).

    The whole file is rewritten (atomically) after every step, so it is valid after each one;
    the cost grows with the number of steps, which is fine for beams (a few thousand points).

    Args:
        path: the ".xdmf" file; an existing one is replaced.
        comm: the communicator whose rank 0 writes.
    """

    def add(self, time, fields):
        """Append the fields of one step at ``time`` and rewrite the file (rank 0)."""
        if self.comm.rank != 0:
            return
        cells = np.asarray(fields["cells"], dtype=np.int64)
        grid = ET.Element("Grid", Name=f"step_{len(self.entries)}", GridType="Uniform")
        ET.SubElement(grid, "Time", Value=repr(float(time)))
        topo = ET.SubElement(
            grid,
            "Topology",
            TopologyType="Polyline",
            NodesPerElement="2",
            NumberOfElements=str(len(cells)),
        )
        _xdmf_item(topo, cells, "Int")
        geo = ET.SubElement(grid, "Geometry", GeometryType="XYZ")
        _xdmf_item(geo, np.asarray(fields["X"]) + np.asarray(fields["u"]), "Float")
        for name, a in _point_arrays(fields).items():
            kind = "Vector" if a.ndim == 2 and a.shape[1] == 3 else "Scalar"
            att = ET.SubElement(grid, "Attribute", Name=name, AttributeType=kind, Center="Node")
            _xdmf_item(att, a, "Int" if a.dtype.kind in "iu" else "Float")
        self._append(grid)

    @staticmethod
    def _read(root):
        series = root.find("Domain").find("Grid")
        return [(float(g.find("Time").get("Value")), g) for g in series.findall("Grid")]

    def _tree(self):
        root = ET.Element("Xdmf", Version="3.0")
        domain = ET.SubElement(root, "Domain")
        series = ET.SubElement(
            domain, "Grid", Name="beam", GridType="Collection", CollectionType="Temporal"
        )
        series.extend(self.entries)
        return root
