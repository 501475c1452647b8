r"""Eigenproblems whose stiffness is a saddle point (a mixed formulation's force unknowns
have no mass): shell operators that keep the massless unknowns out of the Krylov space.

With K = [[A, Bᵀ], [B, −S]] and M, G zero on the force rows and columns, the problem in the
displacement unknowns alone is the condensed one, K_c = A + Bᵀ S⁻¹ B (the displacement
form's matrix), but K_c⁻¹ v is the displacement part of a solve with the saddle point:
K⁻¹ [v; 0]. That solve does not lose the digits that K_c's entries (EA/h, GA/h) cost. The
force directions themselves are infinite eigenvalues whose chains grow as S → 0 (nearly
defective: S⁻¹ is the stiffness); a Krylov space that holds them returns eigenvalues with
small backward errors that are nonetheless wrong. On SM 2.10's blade (8 × P3, shear
1e5·EI/L², at rest, against the mixed model's modal frequencies) SLEPc's TOAR missed by 4e-1
(spurious modes), with ``pep_scale both`` by 4e-7 (1e-6 at EA, GA ×1e4), ``pep_type linear``
by 5e-2, this module's companion form with the projection below by 1e-12 (without it: 2e-2
at Ω = ω_By); STOAR and ``pep_refine simple`` fail with SLEPc error 56 on this non-Hermitian
problem. Zeroing the massless unknowns ``massless`` (local indices) of every vector the
operator returns (the projection P) removes them:

* :func:`solve_eigen_massless`: K x = θ M x nearest 0, as P K⁻¹ M P (eigenvalue 1/θ);
* :func:`solve_quadratic_massless`: (λ² M + λ G + K) x = 0 nearest 0, as the first companion
  form inverted at 0, [x; y] ↦ P [−K⁻¹(s G x + s² M y); x] with y = ν x, λ = s ν (eigenvalue
  1/ν; s a scale near the wanted |λ|).

The returned eigenvectors are completed with their massless part (one more solve), so they
are eigenvectors of the full problem, and the residuals are its backward errors.
Constrained rows (identity in K, zero in G and M) are nilpotent directions of both operators
(at 1/θ = 0), as in shift-and-invert. Knows nothing of beams.
"""

import time

import numpy as np

from .eigen import EigenPairs, solve_and_collect
from .options import petsc_options
from .quadratic import QuadraticPairs

DEFAULT_OPTIONS = {"eps_type": "krylovschur", "eps_tol": 1e-12, "eps_max_it": 300}
#: the factorisation of K (options under the prefix + "lin_")
LINEAR_OPTIONS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


class _Shell:
    """A factorised K, work vectors and the projection on the unknowns with mass."""

    def __init__(self, K, prefix, massless):
        from petsc4py import PETSc

        self.ksp = PETSc.KSP().create(K.getComm())
        self.ksp.setOptionsPrefix(prefix + "lin_")
        self.ksp.setOperators(K)
        with petsc_options(prefix + "lin_", LINEAR_OPTIONS):
            self.ksp.setFromOptions()
        self.ksp.setUp()
        self.a, self.b = K.createVecs()
        self.c, self.sol = K.createVecs()
        self.n = self.a.getLocalSize()
        self.massless = np.asarray([] if massless is None else massless, dtype=np.int32)

    def solve(self, rhs):
        """K⁻¹ rhs (a Vec) as a NumPy array (local part, a copy)."""
        self.ksp.solve(rhs, self.sol)
        return self.sol.getArray(readonly=True).copy()

    def times(self, A, x, out):
        """A x for a NumPy array ``x`` (local part), into ``out`` (returned)."""
        self.a.array[:] = x
        A.mult(self.a, out)
        return out

    def project(self, x):
        """Zero the massless unknowns of ``x`` (in place)."""
        x[self.massless] = 0.0
        return x

    def matrix(self, size):
        """The shell matrix of ``size`` local blocks of n (self as its Python context)."""
        from petsc4py import PETSc

        N = self.a.getSize()
        local, total = size * self.n, size * N
        A = PETSc.Mat().createPython(((local, total), (local, total)), self, self.a.getComm())
        A.setUp()
        return A

    def release(self):
        """Free the factorisation and the work vectors."""
        for obj in (self.ksp, self.a, self.b, self.c, self.sol):
            obj.destroy()


class _Inverse(_Shell):
    """x ↦ P K⁻¹ M x."""

    def __init__(self, K, M, prefix, massless):
        super().__init__(K, prefix, massless)
        self.M = M

    def mult(self, mat, X, Y):
        """Y = P K⁻¹ M X."""
        Y.getArray()[:] = self.project(self.solve(self.times(self.M, X.getArray(True), self.b)))


class _Companion(_Shell):
    """[x; y] ↦ P [−K⁻¹(s G x + s² M y); x]."""

    def __init__(self, K, G, M, s, prefix, massless):
        super().__init__(K, prefix, massless)
        self.G, self.M, self.s = G, M, s

    def mult(self, mat, X, Y):
        """Y = the operator times X."""
        n, s, a = self.n, self.s, X.getArray(readonly=True)
        rhs = self.times(self.G, a[:n], self.b)
        rhs.scale(s)
        rhs.axpy(s * s, self.times(self.M, a[n:], self.c))
        out = Y.getArray()
        out[:n] = -self.project(self.solve(rhs))
        out[n:] = self.project(a[:n].copy())


def _run(op, blocks, nev, prefix, options):
    """Krylov–Schur for the ``nev`` largest eigenvalues of the shell ``op``: (values, first
    block of each vector as complex arrays, iterations)."""
    from slepc4py import SLEPc

    A = op.matrix(blocks)
    eps = SLEPc.EPS().create(A.getComm())
    eps.setOptionsPrefix(prefix)
    eps.setOperators(A)
    eps.setProblemType(SLEPc.EPS.ProblemType.NHEP)
    eps.setDimensions(nev=nev)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_MAGNITUDE)
    # the operator is inverted already: no spectral transform, whatever the options say
    with petsc_options(prefix, {**DEFAULT_OPTIONS, **(options or {}), "st_type": "shift"}):
        eps.setFromOptions()
    n = op.n

    def keep(vr, vi):
        return vr.getArray()[:n] + 1j * vi.getArray()[:n]

    try:
        mus, vectors, _, its = solve_and_collect(eps, A, nev, prefix, keep)
    finally:
        A.destroy()
    return np.asarray(mus, dtype=complex), vectors, its


def _complete(op, lam, x, apply):
    """The full eigenvector −K⁻¹ r of the displacement part ``x`` (complex), r = apply(λ, x)
    (the mass-side terms, zero on the massless rows): real and imaginary part, one solve each.
    """
    r = apply(lam, x)
    out = []
    for part in (r.real, r.imag):
        op.b.array[:] = part
        out.append(op.solve(op.b))
    return -(out[0] + 1j * out[1])


def _apply(op, mats):
    """(λ, x) ↦ Σ_k λ^(k+1) mats[k] x for complex λ and x (local arrays)."""

    def apply(lam, x):
        total = np.zeros(len(x), dtype=complex)
        for k, A in enumerate(mats):
            total += lam ** (k + 1) * complex_mult(A, x, op.a, op.c)
        return total

    return apply


def complex_mult(A, v, x, y):
    """A v for a complex array ``v`` (local part), through the work Vecs ``x`` and ``y``."""
    x.array[:] = v.real
    A.mult(x, y)
    re = y.getArray().copy()
    x.array[:] = v.imag
    A.mult(x, y)
    return re + 1j * y.getArray()


def backward_errors(K, terms, values, vectors):
    """‖P(λ)x‖ / (Σ_k |λ|^k ‖A_k‖ ‖x‖) of each pair, P(λ) = K + Σ_k λ^(k+1) terms[k] (x complex,
    local parts; Frobenius norms). Collective."""
    from petsc4py import PETSc

    comm = K.getComm().tompi4py()
    mats = (K, *terms)
    norms = [A.norm(PETSc.NormType.FROBENIUS) for A in mats]
    x, y = K.createVecs()
    out = []
    for lam, v in zip(values, vectors):
        r = sum(lam**k * complex_mult(A, v, x, y) for k, A in enumerate(mats))
        num = comm.allreduce(float(np.vdot(r, r).real))
        den = comm.allreduce(float(np.vdot(v, v).real))
        scale = sum(abs(lam) ** k * a for k, a in enumerate(norms))
        out.append(np.sqrt(num / den) / scale if den > 0 else np.inf)
    for v in (x, y):
        v.destroy()
    return np.asarray(out)


def massless_rows(M):
    """Owned local indices whose row and column of M are zero (no mass: the force unknowns of a
    mixed form, rotations without rotary inertia, hinges, constrained rows). Collective."""
    from petsc4py import PETSc

    Mt = M.transpose(PETSc.Mat())  # without ``out`` petsc4py transposes M in place
    zero = []
    for A in (M, Mt):
        ai, _, av = A.getValuesCSR()
        nonzero = np.add.reduceat(np.abs(np.r_[av, 0.0]), ai[:-1]) * (np.diff(ai) > 0)
        zero.append(nonzero == 0.0)
    Mt.destroy()
    return np.flatnonzero(zero[0] & zero[1]).astype(np.int32)


def solve_eigen_massless(K, M, nev, prefix, massless, options=None, shift=0.0):
    """The ``nev`` eigenpairs of K x = θ M x nearest ``shift`` with the ``massless`` unknowns
    (local indices; M is zero on their rows and columns) kept out of the Krylov space (module
    doc). A nonzero ``shift`` σ factorises K − σ M instead of K (a free structure's K is
    singular: σ < 0 below its rigid-body modes at 0) and adds σ back to the eigenvalues.

    Returns:
        :class:`~beamfx.solvers.eigen.EigenPairs`; its vectors are complex NumPy arrays
        (local parts, massless part completed), nearest ``shift`` first; residuals are the
        backward errors of the shifted problem.
    """
    t = time.perf_counter()
    if shift:
        K = K.copy()
        K.axpy(-shift, M)
    try:
        pairs = _eigen_massless(K, M, nev, prefix, massless, options)
    finally:
        if shift:
            K.destroy()
    return pairs._replace(values=pairs.values + shift, seconds=time.perf_counter() - t)


def _eigen_massless(K, M, nev, prefix, massless, options):
    """:func:`solve_eigen_massless` at shift 0."""
    t = time.perf_counter()
    op = _Inverse(K, M, prefix, massless)
    try:
        mus, xs, its = _run(op, 1, nev, prefix, options)
        values = 1.0 / mus
        # K x = θ M x_u: x = θ K⁻¹ M x_u
        xs = [-_complete(op, lam, x, _apply(op, [M])) for lam, x in zip(values, xs)]
        M_neg = M.copy()
        M_neg.scale(-1.0)
        errors = backward_errors(K, [M_neg], values, xs)
        M_neg.destroy()
    finally:
        op.release()
    order = np.argsort(np.abs(values), kind="stable")
    return EigenPairs(
        values[order], tuple(xs[i] for i in order), errors[order], its, time.perf_counter() - t
    )


def solve_quadratic_massless(K, G, M, nev, prefix, massless, options=None, scale=None):
    """The ``nev`` eigenpairs of (λ² M + λ G + K) x = 0 nearest 0 with the ``massless``
    unknowns (local indices; G and M are zero on their rows and columns) kept out of the
    Krylov space (module doc). ``scale``: the factor s of λ = s ν, default sqrt|θ| of the
    (``nev`` // 2)-th eigenvalue of K x = θ M x (:func:`solve_eigen_massless`).

    Returns:
        :class:`~beamfx.solvers.quadratic.QuadraticPairs` nearest 0 first, each vector as
        (real part, imaginary part) NumPy arrays with its massless part completed; residuals
        are backward errors. In real arithmetic a complex λ comes with its conjugate.
    """
    t = time.perf_counter()
    if scale is None:
        k = max(nev // 2, 1)
        theta = solve_eigen_massless(K, M, k, prefix + "scale_", massless)
        top = float(np.max(np.abs(theta.values[:k])))  # more may have converged, far ones
        scale = np.sqrt(top) if top > 0 else 1.0
    op = _Companion(K, G, M, float(scale), prefix, massless)
    try:
        mus, xs, its = _run(op, 2, nev, prefix, options)
        values = scale / mus
        xs = [_complete(op, lam, x, _apply(op, [G, M])) for lam, x in zip(values, xs)]
    finally:
        op.release()
    errors = backward_errors(K, [G, M], values, xs)
    order = np.argsort(np.abs(values), kind="stable")
    return QuadraticPairs(
        values[order],
        tuple((xs[i].real.copy(), xs[i].imag.copy()) for i in order),
        errors[order],
        its,
        time.perf_counter() - t,
    )
