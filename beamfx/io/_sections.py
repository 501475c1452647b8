"""One compiled expression of the section quantities that probes and field output share.

The expression is a flat UFL vector of, per point of the reference cell:

=========  ====  =================================================================
name       size  meaning
=========  ====  =================================================================
``X``      3     reference centre line (the mesh is the reference configuration)
``u``      3     displacement (global axes)
``rot``    4/3   quaternion ``q`` (finite kinematics) or rotation vector ``θ`` (linear)
``Lam0``   9     reference section frame Λ0, row-major, columns (t0, e2, e3)
``N``      3     section force C_N Γ (section axes)
``M``      3     section moment C_M K (section axes)
=========  ====  =================================================================

N and M are recovered from the Gauss points of the cell by default (:func:`evaluate`). The
expression is compiled once per model and set of reference points (cached on the model
object, so a per-step writer compiles nothing). The current section axes R·Λ0 are formed in
NumPy from ``rot`` and ``Lam0`` (:func:`rotation_matrices`). Within
:func:`shared_evaluation` the consumers of one state (a static step's probes, reactions and
frame) read one evaluation of all owned cells instead of evaluating their own cells each.
"""

import weakref
from contextlib import contextmanager
from functools import lru_cache

import numpy as np
import ufl

from ..physics.rotations import np_exp_rotation, np_rotation
from ..solvers.forms import JIT_PARAMS

_compiled = weakref.WeakKeyDictionary()  # model -> {points key: (Expression, layout)}
_shared = weakref.WeakKeyDictionary()  # model -> its _SharedEvaluation (see shared_evaluation)


def _layout(kin):
    sizes = {"X": 3, "u": 3, "rot": kin.output_rotation_size, "Lam0": 9, "N": 3, "M": 3}
    layout, start = {}, 0
    for name, n in sizes.items():
        layout[name] = slice(start, start + n)
        start += n
    return layout, start


def section_expression(model):
    """Flat UFL vector of the quantities in the module table, and its layout (name -> slice)."""
    parts = model.section_parts()
    flat = [p[index] for p in parts for index in np.ndindex(p.ufl_shape)]  # row-major
    layout, size = _layout(model.kin)
    assert len(flat) == size  # internal consistency of the table above
    return ufl.as_vector(flat), layout


@lru_cache
def cell_nodes(degree):
    """The k + 1 equispaced nodes ξ = 0, 1/k, ..., 1 of a cell, shape (k + 1, 1): the points
    of the frames and of the probes (one compiled expression serves both)."""
    nodes = np.linspace(0.0, 1.0, degree + 1)[:, None]
    nodes.flags.writeable = False
    return nodes


@lru_cache
def gauss_points(degree):
    """The ``degree`` Gauss–Legendre points on [0, 1]: the shear/axial rule of the model
    (cached; read only)."""
    g, _ = np.polynomial.legendre.leggauss(degree)
    g = (g + 1) / 2
    g.flags.writeable = False
    return g


def lagrange_matrix(nodes, x):
    """Values at ``x`` of the Lagrange polynomials through ``nodes``, shape (len(x), len(nodes))."""
    A = np.ones((len(x), len(nodes)))
    for j, xj in enumerate(nodes):
        for i, xi in enumerate(nodes):
            if i != j:
                A[:, j] *= (x - xi) / (xj - xi)
    return A


def evaluate(model, points, cells, recover=True, full=True):
    r"""Section quantities at reference ``points`` (shape (n, 1)) of local ``cells``.

    With ``recover`` (the default) N and M are not taken pointwise but recovered: sampled at
    the k Gauss points of the cell (k the degree; the rule that integrates the shear and axial
    energy, the points where the stress resultants are most accurate, Barlow 1976) and
    extended to ``points`` by the polynomial of degree k − 1 through them. Pointwise values at
    the cell ends oscillate: in the pure-moment roll-up (to a half circle, 8 quadratic
    elements) the nodal N reaches 3 M/L and M is off by 0.3 %; recovered, N is zero to the
    solver tolerance and M is off by 2e-5 (8 cubic elements: 6e-6 pointwise, 3e-6 recovered).

    Collective the first time for a given model and points (JIT compilation); afterwards
    purely local. Ghost values of ``model.w`` must be up to date (the solvers scatter them).

    With ``full=False`` only ``X``, ``u`` and ``rot`` are returned (the same compiled
    expression, the same values), without the recovery and the section axes: what a probe
    history needs at every step.

    Returns:
        dict name -> array of shape (len(cells), len(points), size), names as in the module
        table plus ``"axes"`` (len(cells), len(points), 3, 3), the current section axes as
        columns.
    """
    points = np.asarray(points, dtype=float).reshape(-1)
    shared = _shared.get(model)
    if shared is not None:
        out = shared.lookup(points, cells, recover, full)
        if out is not None:
            return out
    values, layout, key = _raw(model, points, cells, recover)
    return _derive(model, values, layout, key[: len(points)], recover, full)


def _raw(model, points, cells, recover):
    """(the compiled expression's values at ``points`` and the Gauss points of ``cells``,
    (cells, points, quantities); its layout; its points as a tuple)."""
    expr, layout, key = section_evaluator(model, points, recover)
    cells = np.asarray(cells, dtype=np.int32)
    size = max(s.stop for s in layout.values())
    if len(cells):
        values = expr.eval(cells).reshape(len(cells), len(key), size)
    else:
        values = np.zeros((0, len(key), size))
    return values, layout, key


def _derive(model, values, layout, points, recover, full, base=None):
    """The dictionary of :func:`evaluate` from the :func:`_raw` ``values`` at ``points`` (a
    tuple); ``base``: such a dictionary of the same values made already (with either
    ``recover``), whose arrays other than N and M are taken as they are."""
    n, cells = len(points), len(values)
    if not full:
        return {name: values[:, :n, layout[name]] for name in ("X", "u", "rot")}
    if base is not None:
        out = dict(base)
        for name in ("N", "M"):
            out[name] = values[:, :n, layout[name]]
    else:
        out = {name: values[:, :n, s] for name, s in layout.items()}
        out["Lam0"] = out["Lam0"].reshape(cells, n, 3, 3)
        rot = out["rot"].reshape(-1, model.kin.output_rotation_size)
        R = rotation_matrices(model.kin.finite, rot)
        out["axes"] = (R @ out["Lam0"].reshape(-1, 3, 3)).reshape(cells, n, 3, 3)
    if recover:
        A = _recovery_matrix(model.degree, points)
        for name in ("N", "M"):
            out[name] = np.einsum("pg,cgi->cpi", A, values[:, n:, layout[name]])
    return out


@contextmanager
def shared_evaluation(model, cells):
    """Within the block, :func:`evaluate` at the cell nodes (:func:`cell_nodes`) of any of
    ``cells`` (local, int32) reads one evaluation of all of them at the model's state, made at
    the first such call: the consumers of one state (a step's probes, reactions and frame)
    evaluate and derive the section quantities once. The values are those of separate calls,
    bit for bit (each cell's are computed alone: the kernel per cell, the rotations and the
    recovery per point), and read only. The state (``w``, the load factor, a condensed
    model's ``u``) must not change inside the block. Not collective; the first evaluation is
    where :func:`evaluate`'s first call would be (every rank makes it)."""
    _shared[model] = _SharedEvaluation(model, cells)
    try:
        yield
    finally:
        _shared.pop(model, None)


class _SharedEvaluation:
    """One state's section quantities at the cell nodes of ``cells`` (see
    :func:`shared_evaluation`), made at the first :meth:`lookup`."""

    def __init__(self, model, cells):
        self.model, self.cells = model, cells
        self.nodes = cell_nodes(model.degree)[:, 0]
        self.rows, self.raw, self.derived = None, None, {}

    def lookup(self, points, cells, recover, full):
        """:func:`evaluate`'s answer, or None if ``points`` are not the cell nodes or a cell
        is not among those shared."""
        if len(points) != len(self.nodes) or not np.array_equal(points, self.nodes):
            return None
        rows = None
        if cells is not self.cells:
            if self.rows is None:  # cell -> its row, -1 for a cell not shared (NumPy, no loop)
                self.rows = np.full(int(self.cells.max(initial=-1)) + 1, -1, dtype=np.int64)
                self.rows[self.cells] = np.arange(len(self.cells))
            cells = np.asarray(cells, dtype=np.int64)
            if len(cells) and (cells.min() < 0 or cells.max() >= len(self.rows)):
                return None
            rows = self.rows[cells]
            if (rows < 0).any():
                return None
        values = self._values(recover)
        if not full:
            values = {name: values[name] for name in ("X", "u", "rot")}
        if rows is None:
            return dict(values)
        if len(rows) == 1:  # (a probe's cell: views, not copies)
            r = slice(int(rows[0]), int(rows[0]) + 1)
            return {name: a[r] for name, a in values.items()}
        return {name: a[rows] for name, a in values.items()}

    def _values(self, recover):
        """The :func:`evaluate` dictionary of all the cells (read only), made once per
        ``recover``: one kernel call for both, the axes shared."""
        if recover not in self.derived:
            if self.raw is None:
                self.raw = _raw(self.model, self.nodes, self.cells, recover)
            values, layout, key = self.raw
            points = key[: len(self.nodes)]
            base = next(iter(self.derived.values()), None)  # the other ``recover``'s
            out = _derive(self.model, values, layout, points, recover, True, base)
            for a in out.values():
                a.flags.writeable = False
            self.derived[recover] = out
        return self.derived[recover]


def section_evaluator(model, points, recover=True):
    """(compiled expression, layout, its points as a tuple) of the module table at reference
    ``points`` (flat), followed by the Gauss points (read with ``recover``): compiled once per model
    and points (collective then), afterwards a look-up. Its ``eval(cells)`` gives, per cell,
    every point's quantities in a row of the layout's size."""
    from dolfinx import fem

    points = np.asarray(points, dtype=float).reshape(-1)
    # the Gauss points even without ``recover`` (whose values are then not read): one
    # compiled expression serves both (a second costs a few ms of every run: UFL signature,
    # FFCx and DOLFINx set-up), and the values at ``points`` come out the same
    sample = np.concatenate([points, gauss_points(model.degree)])
    key = tuple(sample.tolist())
    per_model = _compiled.setdefault(model, {})
    if key not in per_model:
        expr_ufl, layout = section_expression(model)
        X = sample.reshape(-1, 1)
        per_model[key] = (fem.Expression(expr_ufl, X, jit_params=dict(JIT_PARAMS)), layout)
    return (*per_model[key], key)


@lru_cache
def _recovery_matrix(degree, points):
    """Values at ``points`` (a tuple) of the Lagrange polynomials through the Gauss points."""
    return lagrange_matrix(gauss_points(degree), np.asarray(points))


def rotation_matrices(finite, rot):
    """Rotation matrices of an (n, 4) array of quaternions (any norm) or an (n, 3) array of
    rotation vectors (linear kinematics): the exact exponential map, so that the drawn section
    axes stay orthonormal where the linear theory's I + hat θ would not."""
    return np_rotation(rot) if finite else np_exp_rotation(rot)
