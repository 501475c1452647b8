"""Free vibration about the current state: det(K − ω² M) = 0.

K is the tangent at ``model.w`` (and the current load factor), so a pre-stressed model gives the
pre-stressed frequencies: run :func:`~beamfx.analyses.static.solve_static` first. M is the mass
form of :mod:`beamfx.physics.inertia` about the same state. Constrained dofs have 1 on K's
diagonal and 0 on M's, so they sit at ω² = ∞.
"""

import time
from typing import NamedTuple

import numpy as np
import ufl

from ..physics import coupled
from ..physics.inertia import mass_form, point_mass_form
from ..solvers.eigen import solve_eigen
from ..solvers.eigen_shell import massless_rows, solve_eigen_massless
from ..solvers.forms import compile_form


class ModalResult(NamedTuple):
    """Eigenvalues ω², frequencies (rad/s, Hz) and modes of a modal analysis."""

    eigenvalues: np.ndarray  # ω² (1/s²), nearest to the target first
    omega: np.ndarray  # rad/s; sign(ω²)·sqrt|ω²|, so a (numerically) negative ω² stays visible
    hz: np.ndarray
    modes: tuple  # dolfinx Functions on model.W (increments of the unknowns)
    residuals: np.ndarray  # SLEPc relative residual per pair
    seconds: dict  # compile, assemble, solve
    mass_form: object = None  # the compiled mass form (for :func:`effective_masses`)


def mass_ufl(model, rotary="full"):
    """The mass form of ``model`` about its current state (UFL): the beams' and the point
    masses' (``rotary`` applies to the sections only; a point mass keeps its inertia)."""
    # displacement and rotation (a third field, the hinges of released joints, has no mass)
    v = ufl.split(ufl.TestFunction(model.W))[:2]
    dw = ufl.split(ufl.TrialFunction(model.W))[:2]
    rot = ufl.split(model.w)[1]
    d = model.discretisation
    if d.matrices is None:
        m = mass_form(model.kin, rot, v, dw, d.inertia, d.Lam0, d.dx, rotary)
    else:
        m = coupled.mass_form(model.kin, rot, v, dw, d.matrices.M, d.Lam0, d.dx, rotary)
    return m + d.point_mass_terms(
        lambda pm: point_mass_form(model.kin, rot, v, dw, pm.mass, pm.inertia)
    )


def assemble_pair(a, b, bcs):
    """A = a with identity on the constrained rows, B = b with zeros there (compiled forms)."""
    import dolfinx.fem.petsc as fp

    A = fp.assemble_matrix(a, bcs=bcs, diagonal=1.0)
    A.assemble()
    B = fp.assemble_matrix(b, bcs=bcs, diagonal=0.0)
    B.assemble()
    return A, B


def is_symmetric(A, rtol=1e-9):
    """Whether ‖A − Aᵀ‖ ≤ rtol ‖A‖ (Frobenius). Collective."""
    from petsc4py import PETSc

    D = A.copy()
    At = A.transpose(PETSc.Mat())  # without ``out`` petsc4py transposes A in place
    D.axpy(-1.0, At)
    ok = D.norm() <= rtol * A.norm()
    for obj in (D, At):
        obj.destroy()
    return ok


def free_shift(K, M, forces=None, length=None):
    """A small negative shift for target 0: a free structure has a singular K.

    min_i K_ii / M_ii (over rows with mass) bounds the lowest ω² from above (Rayleigh quotient
    of a unit vector); 1e-6 of it is far below the lowest elastic ω² of any mesh one would run,
    yet far above the round-off of the rigid-body eigenvalues. The mixed formulation's
    displacement rows have K_ii = 0 (their stiffness is the coupling to the force unknowns):
    there :func:`row_stiffness` stands for K_ii, which it equals for a positive definite K.
    That coupling grows as the compliance 1/EA, 1/GA goes to 0 (the row's stiffness EA/h²),
    while the lowest elastic ω² tends to the rigid limit's: the columns ``forces`` (global
    indices of the force unknowns) do not count, and the scale is the rigid limit's,
    independent of EA and GA. If that leaves no row with both stiffness and mass (rotations
    without rotary inertia, at rest), :func:`bending_scale` with the shortest cell ``length``.
    """
    comm = K.getComm().tompi4py()
    m = M.getDiagonal()
    ma = m.getArray().copy()
    m.destroy()
    local = np.inf
    if forces is not None:
        local = _min_ratio(comm, row_stiffness(K, forces), ma)
        if not np.isfinite(local) and length is not None:
            local = bending_scale(K, ma, forces, length)
    if not np.isfinite(local):
        local = _min_ratio(comm, row_stiffness(K), ma)
    return -1e-6 * local


def _min_ratio(comm, k, m):
    """The smallest k_i / m_i over the rows with mass and stiffness (all ranks; inf if none)."""
    from mpi4py import MPI

    ratio = k[m > 0] / m[m > 0]
    ratio = ratio[ratio > 0]
    return comm.allreduce(np.min(ratio) if len(ratio) else np.inf, op=MPI.MIN)


def bending_scale(K, m, forces, length):
    """The rigid limit's bending scale EI/(ρA h⁴) from the matrices: the smallest diagonal of
    the rows with stiffness but no mass (rotations without rotary inertia: EI/h; not the
    ``forces``, not the constrained rows, identity rows) over the largest diagonal mass (ρA h)
    times ``length``² (h). In the rigid limit a translation moves with the rotations; this
    is the highest bending ω² of the mesh, so 1e-6 of it lies below the lowest elastic ω² of
    any mesh one would run. Collective."""
    from mpi4py import MPI

    comm = K.getComm().tompi4py()
    start = K.getOwnershipRange()[0]
    ai, aj, av = K.getValuesCSR()
    rows = np.repeat(np.arange(len(ai) - 1), np.diff(ai))
    diagonal = aj == rows + start
    d = np.zeros(len(ai) - 1)
    d[rows[diagonal]] = av[diagonal]
    coupled = np.zeros(len(ai) - 1, dtype=bool)
    coupled[rows[~diagonal & (av != 0.0)]] = True
    owned = np.ones(len(ai) - 1, dtype=bool)
    local_forces = forces - start
    owned[local_forces[(local_forces >= 0) & (local_forces < len(owned))]] = False
    keep = owned & coupled & (d > 0) & (m == 0)
    k = comm.allreduce(np.min(d[keep]) if keep.any() else np.inf, op=MPI.MIN)
    top = comm.allreduce(float(np.max(m, initial=0.0)), op=MPI.MAX)
    return k / (top * length**2) if top > 0 else np.inf


def force_columns(model, K):
    """Global indices (all ranks) of the mixed form's section force unknowns, or None."""
    from .mixed import owned_force_dofs

    owned = owned_force_dofs(model)
    if owned is None:
        return None
    rows = np.asarray(owned, dtype=np.int64) + K.getOwnershipRange()[0]
    return np.concatenate(K.getComm().tompi4py().allgather(rows))


def row_stiffness(K, skip=None):
    """Per owned row i: max(|K_ii|, max_j K_ij² / |K_jj|) over the columns with K_jj ≠ 0 (and
    not in ``skip``, global indices). For a positive semi-definite K that is K_ii
    (Cauchy–Schwarz); for a saddle-point tangent's rows with a zero diagonal, the stiffness
    their coupling gives them. Collective."""
    comm = K.getComm().tompi4py()
    diag = K.getDiagonal()
    d = np.abs(np.concatenate(comm.allgather(diag.getArray().copy())))
    diag.destroy()
    if skip is not None:
        d[skip] = 0.0
    start = K.getOwnershipRange()[0]
    ai, aj, av = K.getValuesCSR()
    with np.errstate(divide="ignore", invalid="ignore"):
        coupled = np.where(d[aj] > 0, av**2 / d[aj], 0.0)
    out = d[start : start + len(ai) - 1].copy()
    full = np.diff(ai) > 0  # CSR rows are contiguous: one reduction per row, not maximum.at
    if len(coupled):
        out[full] = np.maximum(out[full], np.maximum.reduceat(coupled, ai[:-1][full]))
    return out


def to_functions(model, vectors):
    """The eigenvectors (PETSc Vec, destroyed here) as Functions ``mode_i`` on ``model.W``."""
    from dolfinx import fem

    modes = []
    for i, x in enumerate(vectors):
        f = fem.Function(model.W, name=f"mode_{i}")
        x.copy(f.vector)
        f.x.scatter_forward()
        x.destroy()
        modes.append(f)
    return tuple(modes)


def solve_modes(
    model, n_modes=6, target=0.0, options=None, prefix="beamfx_modal_", rotary="full", shift=None
):
    """The ``n_modes`` vibration modes with ω² nearest to ``target`` (1/s²), about ``model.w``.

    Krylov–Schur with shift-and-invert (MUMPS). At target 0 the shift defaults to a small
    negative value (:func:`free_shift`), so that a free structure, whose K is singular, works:
    its six rigid-body modes come out with ω² ≈ 0. ``rotary`` as in
    :data:`beamfx.physics.inertia.ROTARY`. The problem is solved as GHEP when K is symmetric
    (conservative loads), else GNHEP (e.g. fixed-axis moments).
    """
    t0 = time.perf_counter()
    K_form, M_form = compile_form(model.J), compile_form(mass_ufl(model, rotary))
    t1 = time.perf_counter()
    K, M = assemble_pair(K_form, M_form, model.bcs)
    t2 = time.perf_counter()
    mixed = getattr(model, "mixed", False)
    if shift is None and target == 0.0:
        length = model.discretisation.min_cell_length() if mixed else None
        shift = free_shift(K, M, force_columns(model, K), length)
    try:
        if mixed:
            pairs = _solve_mixed(K, M, n_modes, target if shift is None else shift, prefix, options)
            modes = arrays_to_functions(model, pairs.vectors[:n_modes])
        else:
            pairs = solve_eigen(
                K,
                M,
                n_modes,
                target,
                prefix,
                options,
                hermitian=is_symmetric(K),
                shift=shift,
                asked=f"{n_modes} modes",
            )
            for x in pairs.vectors[n_modes:]:
                x.destroy()
            modes = to_functions(model, pairs.vectors[:n_modes])
    finally:
        K.destroy()
        M.destroy()
    lam = pairs.values.real[:n_modes]
    omega = np.sign(lam) * np.sqrt(np.abs(lam))
    seconds = {"compile": t1 - t0, "assemble": t2 - t1, "solve": pairs.seconds}
    residuals = pairs.residuals[:n_modes]
    return ModalResult(lam, omega, omega / (2 * np.pi), modes, residuals, seconds, M_form)


def _solve_mixed(K, M, n_modes, shift, prefix, options):
    """The mixed form's modes: the unknowns without mass (the section forces, and rotations
    without rotary inertia) kept out of the Krylov space, K − σM factorised
    (:func:`~beamfx.solvers.eigen_shell.solve_eigen_massless`). Shift-and-invert on the saddle
    point holds them in it: as the compliance goes to 0 they become nearly defective infinite
    eigenvalues and SLEPc converged 0 of 6 pairs (SM 2.10's blade, EA, GA × 1e8). The pairs
    nearest σ, the ω² of the structure (real parts; a complex pair from a non-conservative
    load keeps its real part, as :func:`solve_eigen` does).

    Should a free shift σ < 0 exceed the spectrum found (a slow, fragile solve), it is
    repeated at −1e-6 of the largest |ω²| found, unless those are rigid modes' round-off."""
    massless = massless_rows(M)
    pairs = solve_eigen_massless(K, M, n_modes, prefix, massless, options, shift=float(shift))
    top = float(np.max(np.abs(pairs.values[:n_modes].real)))
    if shift < 0 and -shift > top > -1e-8 * shift:  # not if only rigid modes (round-off) came
        again = solve_eigen_massless(K, M, n_modes, prefix, massless, options, shift=-1e-6 * top)
        pairs = again._replace(seconds=pairs.seconds + again.seconds)
    return pairs


def arrays_to_functions(model, vectors):
    """The eigenvectors (complex NumPy arrays, owned parts) as Functions ``mode_i`` on
    ``model.W`` (their real parts)."""
    from dolfinx import fem

    modes = []
    for i, x in enumerate(vectors):
        f = fem.Function(model.W, name=f"mode_{i}")
        f.vector.array[:] = np.real(x)
        f.x.scatter_forward()
        modes.append(f)
    return tuple(modes)


def effective_masses(model, modes, rotary="full", mass_form=None):
    r"""Effective modal masses for base excitation along x, y, z (kg), per mode:
    :math:`m_{k,d} = (φ_k^T M r_d)^2 / (φ_k^T M φ_k)`, with :math:`r_d` the rigid translation
    of the free dofs along axis d (u_d = 1, rotations unchanged). Summed over all modes they
    give the mass that moves with the base, so their fractions tell how many modes a base
    excitation response needs. Meaningful for supported structures (a free one's rigid-body
    modes take the whole mass). ``mass_form``: the compiled mass form of ``model`` and
    ``rotary`` (:attr:`ModalResult.mass_form`; built here if None: building and signing it
    again costs 4 ms, a sixth of a small modal run). Collective.
    """
    import dolfinx.fem.petsc as fp

    from ..spec import DOF_NAMES
    from .dofs import displacement_components, owned_size, subspace_dofs

    if mass_form is None:
        mass_form = compile_form(mass_ufl(model, rotary))
    M = fp.assemble_matrix(mass_form, bcs=model.bcs, diagonal=0.0)
    M.assemble()
    r, Mr, Mphi = M.createVecRight(), M.createVecLeft(), M.createVecLeft()
    owned = owned_size(model.W)
    sub_of = displacement_components(model.kin)
    out = np.zeros((len(modes), 3))
    for d, name in enumerate(DOF_NAMES[:3]):
        if name not in sub_of:  # out of the planar model's plane
            continue
        dofs = subspace_dofs(model.W, 0, sub_of[name])
        r.set(0.0)
        r.array[dofs[dofs < owned]] = 1.0
        M.mult(r, Mr)
        for k, mode in enumerate(modes):
            M.mult(mode.vector, Mphi)
            out[k, d] = Mr.dot(mode.vector) ** 2 / Mphi.dot(mode.vector)
    for obj in (M, r, Mr, Mphi):
        obj.destroy()
    return out
