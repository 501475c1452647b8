"""VTK XML files through VTK's own writers.

Data files (``.vtu`` and the ``.pvtu`` summary of a parallel frame) are written by VTK
(``vtkXMLUnstructuredGridWriter``, ``vtkXMLPUnstructuredGridWriter``): binary, compressed,
appended, 64-bit headers. VTK makes each file in memory (2.5 times faster than its own file
output for a small frame). A single file (:func:`write_grid`) goes to a temporary name and is
then renamed, so a reader never sees half a file; the frames of a series (:class:`GridWriter`,
and the summaries of :func:`write_summary`) are written under their own name, since a reader
finds them through the series' index, which names a frame only after its files are complete
(the rename cost as much as the file's creation: 0.15-0.4 ms a frame here).

Compression is LZ4, not zlib. Measured on the frames of a real state (flying spaghetti, 16 P2
elements, a rectangle section; VTK's Write alone, CPU, the arrays changed as in a frame, with
:func:`thread_count_once`):

========================  ============  ============  ============  ============
frame                     none          LZ4           zlib 1        zlib 6
========================  ============  ============  ============  ============
centre line (48 points)   0.06 ms 12.8k 0.07 ms 11.8k 0.24 ms 10.3k 0.39 ms 10.2k
surface (320 points)      0.05 ms 47.5k 0.08 ms 28.0k 0.33 ms 16.3k 0.75 ms 15.9k
reactions (1 point)       0.03 ms 1.6k  0.04 ms 1.8k  0.05 ms 1.8k  0.05 ms 1.8k
========================  ============  ============  ============  ============

(zlib levels 2-5 lie between; bytes in thousands.) zlib makes the surface files 40 % smaller
than LZ4 but VTK's writing 3-4 times dearer; ParaView 5.11 (Debian 12, the pvpython checks of
the tests) and the vtk wheel read LZ4.

Under MPI every rank writes its own piece ``name_NNNN_R.vtu`` (the cells it owns) and rank 0
the summary ``name_NNNN.pvtu``; nothing is gathered. Without an MPI controller (the pip wheel
has none) VTK's parallel writer lists only the pieces it wrote itself, so once per series rank
0 lets it write the summary of all ranks' pieces from a one-point stand-in of its own piece in
a scratch folder; every frame's summary is that file with the frame's piece names.

The time series (``.pvd`` index and frame files) are in :mod:`beamfx.io.series`.

Import :func:`import_vtk` before DOLFINx in one process: DOLFINx loads its libraries with
RTLD_GLOBAL, and the VTK wheel's libstdc++ pieces then clash with Debian's. With DOLFINx first,
writing and reading these files worked in our tests but rendering aborted (std::bad_alloc);
with these three VTK modules first, rendering in the same process works too. They add about
0.1 s to the start of a process (median of 8: ``import dolfinx`` 0.69 s, with them 0.79 s).
"""

import errno
import os
import tempfile
from functools import lru_cache

import numpy as np

VTK_VERTEX, VTK_LINE, VTK_POLYGON, VTK_QUAD, VTK_LAGRANGE_CURVE = 1, 3, 7, 9, 68


class OutputUnavailable(OSError):
    """The frames cannot be written (a library is missing): raised before the solve."""


def import_vtk():
    """Import the VTK modules the writers need (call it before DOLFINx is imported).

    Raises:
        OutputUnavailable: if VTK is not installed, naming the package to install.
    """
    try:
        import vtkmodules.vtkCommonCore
        import vtkmodules.vtkCommonDataModel
        import vtkmodules.vtkIOXML  # noqa: F401
    except ImportError as e:
        raise OutputUnavailable(
            f"the ParaView output needs VTK's Python wheel ({e}): pip install vtk, or leave "
            'out the VTK formats ([output] formats = ["xdmf"] or [])'
        ) from None
    thread_count_once()


@lru_cache(maxsize=1)
def thread_count_once():
    """Tell VTK's STDThread backend its number of threads once, the number it would find
    itself (``vtkSMPTools.GetEstimatedNumberOfThreads``), and keep the backend in use.

    Why: every array range a writer computes (the RangeMin/RangeMax of each array of each
    file) builds VTK's thread-local storage for every backend, and the STDThread one asks
    ``std::thread::hardware_concurrency()`` unless its count was set; with glibc that reads
    ``/sys/devices/system/cpu/online``: 20 reads for a centre-line frame of 10 arrays,
    2/3 of VTK's cost of writing it (vtk 9.7.2 wheel: 0.21-0.31 ms a file, 0.07 ms with the
    count set; the files are byte for byte the same). VTK's own default backend is
    Sequential; a process that picked another one (``VTK_SMP_BACKEND_IN_USE``) keeps it.
    """
    from vtkmodules.vtkCommonCore import vtkSMPTools

    active = vtkSMPTools.GetBackend()
    if not vtkSMPTools.SetBackend("STDThread"):  # a VTK built without it: nothing asks
        return
    try:
        vtkSMPTools.Initialize(vtkSMPTools.GetEstimatedNumberOfThreads())
    finally:
        vtkSMPTools.SetBackend(active)


def _vtk_array(a, name=None):
    """A VTK array on the memory of a private contiguous copy of ``a`` (kept alive by it)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk

    a = np.array(a, order="C")
    v = numpy_to_vtk(a.reshape(len(a), -1) if a.ndim > 1 else a)
    if name:
        v.SetName(name)
    return v


def unstructured_grid(points, connectivity, offsets, types, point_data=None, cell_data=None):
    """A ``vtkUnstructuredGrid`` from NumPy arrays.

    Args:
        points: (n, 3) coordinates.
        connectivity: point indices of all cells, one after another.
        offsets: (cells + 1,) start of each cell in ``connectivity``, then its length.
        types: (cells,) VTK cell types.
        point_data: ``{name: array}`` with n rows.
        cell_data: ``{name: array}`` with one row per cell.
    """
    from vtkmodules.util.numpy_support import numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkUnstructuredGrid

    grid = vtkUnstructuredGrid()
    pts = vtkPoints()
    pts.SetData(_vtk_array(np.asarray(points, float).reshape(-1, 3)))
    grid.SetPoints(pts)
    cells = vtkCellArray()
    ids = [np.array(a, dtype=np.int64) for a in (offsets, connectivity)]
    cells.SetData(numpy_to_vtkIdTypeArray(ids[0]), numpy_to_vtkIdTypeArray(ids[1]))
    grid.SetCells(_vtk_array(np.asarray(types, np.uint8)), cells)
    for data, target in ((point_data, grid.GetPointData()), (cell_data, grid.GetCellData())):
        for name, a in (data or {}).items():
            target.AddArray(_vtk_array(a, name))
    if point_data and "u" in point_data:
        grid.GetPointData().SetActiveVectors("u")
    return grid


class GridBuffer:
    """The grid of a series, reused from frame to frame: when the cells and array names are
    those of the previous frame, the new points and arrays are copied into the memory of its
    VTK arrays instead of building new ones (a third of a frame's cost for a small beam)."""

    def __init__(self):
        self.grid, self.cells, self.buffers = None, None, {}

    def __call__(self, points, connectivity, offsets, types, point_data=None, cell_data=None):
        """The grid of these arrays (see :func:`unstructured_grid`); valid until the next call."""
        from vtkmodules.util.numpy_support import vtk_to_numpy

        point_data, cell_data = point_data or {}, cell_data or {}
        cells = (np.asarray(connectivity), np.asarray(offsets), np.asarray(types))
        names = (tuple(point_data), tuple(cell_data))
        same = self.grid is not None and self.names == names and len(points) == self.n
        if same and all(a is b or np.array_equal(a, b) for a, b in zip(cells, self.cells)):
            for a, buffer in zip((points, *point_data.values(), *cell_data.values()), self.buffers):
                np.copyto(buffer, np.asarray(a).reshape(buffer.shape))
            for v in self.vtk_arrays:
                v.Modified()
            self.grid.Modified()
            return self.grid
        grid = unstructured_grid(points, *cells, point_data, cell_data)
        pd, cd = grid.GetPointData(), grid.GetCellData()
        self.vtk_arrays = [grid.GetPoints().GetData()]
        self.vtk_arrays += [pd.GetArray(n) for n in point_data] + [
            cd.GetArray(n) for n in cell_data
        ]
        self.buffers = [vtk_to_numpy(v) for v in self.vtk_arrays]
        self.grid, self.cells, self.names, self.n = (
            grid,
            tuple(a if not a.flags.writeable else a.copy() for a in cells),
            names,
            len(points),
        )
        return grid


@lru_cache(maxsize=16)
def _line_cells(n_cells, k):
    """(connectivity, offsets, types) of ``n_cells`` line cells of k + 1 consecutive points
    (cached, read only: a series asks for the same cells at every frame)."""
    order = np.array([0, k, *range(1, k)]) if k > 1 else np.array([0, 1])
    conn = ((k + 1) * np.arange(n_cells)[:, None] + order[None, :]).ravel()
    offsets = (k + 1) * np.arange(n_cells + 1)
    types = np.full(n_cells, VTK_LAGRANGE_CURVE if k > 1 else VTK_LINE)
    for a in (conn, offsets, types):
        a.flags.writeable = False
    return conn, offsets, types


def lagrange_line_grid(points, degree, point_data, cell_data, build=unstructured_grid):
    """Grid of line cells of ``degree`` + 1 consecutive points each (ξ = 0, 1/k, ..., 1):
    VTK_LAGRANGE_CURVE, whose point order is the two ends, then the interior nodes
    (VTK_LINE for k = 1); made by ``build`` (:func:`unstructured_grid` or a
    :class:`GridBuffer`)."""
    cells = _line_cells(len(points) // (degree + 1), degree)
    return build(points, *cells, point_data, cell_data)


def write_grid(path, grid):
    """``grid`` to the ``.vtu`` file ``path`` (binary, LZ4, appended), through a rename."""
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    thread_count_once()
    _write(vtkXMLUnstructuredGridWriter(), os.fspath(path), grid)


def write_vtu(path, fields, comm=None):
    """The centre line of gathered fields (:func:`~beamfx.io.fields.nodal_fields`) as one
    ``.vtu`` of Lagrange curves, written by rank 0 of ``comm`` (default: all ranks)."""
    from mpi4py import MPI

    if (comm or MPI.COMM_WORLD).rank != 0:
        return
    n, segments = len(fields["X"]), len(fields["cells"])
    k = segments // (n - segments)  # n = elements·(k + 1) points, elements·k segments
    point_data = {name: fields[name] for name in ("X", "u", "e1", "e2", "e3", "N", "M")}
    beam = np.asarray(fields["beam"]).reshape(n - segments, k + 1)[:, 0].astype(np.int64)
    cell_data = {"cell": np.arange(n - segments), "beam": beam}
    points = np.asarray(fields["X"]) + np.asarray(fields["u"])
    write_grid(path, lagrange_line_grid(points, k, point_data, cell_data))


def _write(writer, path, grid, rename=True, configured=False):
    """Let ``writer`` make the file in memory (2.5 times faster than VTK's own file output
    for a small frame), then write it (to a temporary name and rename it, if ``rename``);
    ``configured``: the writer's modes are set already (:func:`_configure`)."""
    if configured:
        writer.SetInputData(grid)
    else:
        _configure(writer, grid)
        writer.WriteToOutputStringOn()
    if not writer.Write():
        raise OSError(f"VTK could not write {path}")
    data = writer.GetOutputString()  # bytes, or str if the bytes happen to be valid UTF-8
    data = data if isinstance(data, bytes) else data.encode("utf-8")
    if not rename:
        write_in_place(path, data)
        return
    target = f"{path}.tmp{os.getpid()}"
    with open(target, "wb") as f:
        f.write(data)
    os.replace(target, path)


def write_in_place(path, data):
    """``data`` as the content of the file ``path``, written over an existing file in place
    (then cut to its length) rather than truncated first: an earlier run's frame of the same
    name costs 13 µs so, 0.2 ms truncated and rewritten, 1-2 ms unlinked and created again
    (ext4 on the machine of the benchmarks). A symbolic link of that name is never followed
    (it could point out of the output folder): it is removed and a file written instead."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_NOFOLLOW
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as e:  # a symbolic link in its place: never written through, replaced
        if e.errno != errno.ELOOP:
            raise
        os.unlink(path)
        fd = os.open(path, flags | os.O_EXCL, 0o666)
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
        os.ftruncate(fd, len(data))
    finally:
        os.close(fd)


class GridWriter:
    """The ``.vtu`` frames of a series: one VTK writer for all of them (a new writer per frame
    cost a fifth of VTK's writing), each file written under its own name (see the module
    docstring: the series' index names a frame only once its file is complete)."""

    def __init__(self):
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

        thread_count_once()  # VTK's writing 3 times cheaper (see there)
        self.writer = vtkXMLUnstructuredGridWriter()
        _configure(self.writer)  # once: setting the modes cost a tenth of a frame
        self.writer.WriteToOutputStringOn()

    def write(self, path, grid):
        """``grid`` to the ``.vtu`` file ``path`` (binary, LZ4, appended)."""
        _write(self.writer, os.fspath(path), grid, rename=False, configured=True)


def _configure(writer, grid=None):
    """Binary, LZ4-compressed appended data with 64-bit headers; the input ``grid`` if given."""
    if grid is not None:
        writer.SetInputData(grid)
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetCompressorTypeToLZ4()
    writer.SetHeaderTypeToUInt64()


def _stand_in(grid):
    """One point and one vertex cell carrying ``grid``'s arrays (names, types, components)."""
    from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid

    one = vtkUnstructuredGrid()
    points = grid.GetPoints().NewInstance()
    points.SetDataType(grid.GetPoints().GetDataType())
    points.SetNumberOfPoints(1)
    points.SetPoint(0, 0.0, 0.0, 0.0)
    one.SetPoints(points)
    one.InsertNextCell(VTK_VERTEX, 1, [0])
    for source, target in (
        (grid.GetPointData(), one.GetPointData()),
        (grid.GetCellData(), one.GetCellData()),
    ):
        for i in range(source.GetNumberOfArrays()):
            a = source.GetArray(i)
            b = a.NewInstance()
            b.SetName(a.GetName())
            b.SetNumberOfComponents(a.GetNumberOfComponents())
            b.SetNumberOfTuples(1)
            b.Fill(0)
            target.AddArray(b)
    return one


PLACEHOLDER = "beamfx-frame"  # the stem of the summary VTK writes once per series


def summary_template(grid, pieces, folder):
    """The ``.pvtu`` summary, as bytes, of a frame ``beamfx-frame`` of ``pieces`` pieces
    ``beamfx-frame_<r>.vtu`` with the arrays of ``grid`` (this rank's piece). Written by VTK's
    parallel writer in a scratch folder inside ``folder`` from a one-point stand-in (see the
    module docstring); only the summary is kept."""
    from vtkmodules.vtkIOParallelXML import vtkXMLPUnstructuredGridWriter

    with tempfile.TemporaryDirectory(dir=folder, prefix=".pvtu") as scratch:
        path = os.path.join(scratch, f"{PLACEHOLDER}.pvtu")
        w = vtkXMLPUnstructuredGridWriter()
        w.SetNumberOfPieces(pieces)
        w.SetStartPiece(0)
        w.SetEndPiece(pieces - 1)
        w.SetWriteSummaryFile(1)
        w.SetFileName(path)
        _configure(w, _stand_in(grid))
        if not w.Write():
            raise OSError(f"VTK could not write the summary of {pieces} pieces in {folder}")
        with open(path, "rb") as f:
            return f.read()


def write_summary(path, template):
    """The ``.pvtu`` at ``path``: the ``template`` with the pieces of this frame, named
    ``<stem>_<r>.vtu`` after the file (the same arrays in every frame of a series). Written
    under its own name, like the pieces (:class:`GridWriter`): the series' index names the
    frame only after this. Through a temporary file and a rename it cost 0.10-0.14 ms a frame
    here, written in place about as much for a new file and 0.013 ms over an earlier run's.
    """
    path = os.fspath(path)
    stem = os.path.splitext(os.path.basename(path))[0]
    text = template.replace(f'Source="{PLACEHOLDER}_'.encode(), f'Source="{stem}_'.encode())
    write_in_place(path, text)


__all__ = [
    "GridBuffer",
    "GridWriter",
    "OutputUnavailable",
    "import_vtk",
    "lagrange_line_grid",
    "summary_template",
    "thread_count_once",
    "unstructured_grid",
    "write_grid",
    "write_summary",
    "write_vtu",
]
