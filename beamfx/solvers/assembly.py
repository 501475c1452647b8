"""Assembly of residual, tangent and load vector with Dirichlet conditions (one place for all
solvers: Newton, arc length, load scaling)."""

import numpy as np


def assemble_residual(
    b, F, J, bcs, x, rows=None, keep=None, targets=None, constants=None, coefficients=None
):
    """Residual b = F with lifting of ``bcs`` about ``x``, b = x - g on constrained rows (b zeroed).

    The Newton correction then drives the constrained dofs to their prescribed values g.
    ``rows``: owned local rows (the constrained ones) whose assembled F (the reactions) is
    measured before it is replaced; returns the local sum of their squares (0 without).
    The lifting is skipped where ``x`` already holds every prescribed value (:func:`lifts`):
    each of its terms is then an exact zero. ``keep``: an array of the owned size that
    receives F before the conditions replace its constrained rows (with the lifting if
    there was one; the return value then says so). ``targets``: the prescribed values on
    ``rows`` (:func:`prescribed`), if the caller knows them; ``constants``: F's constants
    packed (``dolfinx.cpp.fem.pack_constants``), if the caller knows they have not changed;
    ``coefficients``: F's coefficients packed (``dolfinx.cpp.fem.pack_coefficients``) at
    this state, if the caller has them.

    DOLFINx's C++ assembler is called directly (its Python wrappers cost more than the
    kernels of a small model), and one rank has no ghosts to add up.

    Returns:
        (local sum of squares of F on ``rows``, whether the lifting was applied).
    """
    import dolfinx.cpp.fem as cpp
    import dolfinx.fem.petsc as fp
    from petsc4py import PETSc

    serial = F.mesh.comm.size == 1
    lift = lifts(bcs, x, rows, targets, serial)
    constants = cpp.pack_constants(F) if constants is None else constants
    if serial:  # no ghost entries: the owned array is the local form's
        _assemble_into(b.array_w, F, constants, coefficients)
    else:
        with b.localForm() as local:
            _assemble_into(local.array_w, F, constants, coefficients)
    if lift:
        fp.apply_lifting(b, [J], bcs=[bcs], x0=[x], scale=-1.0)
    if not serial:
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    local = 0.0
    if keep is not None or (rows is not None and len(rows)):
        owned = b.getArray(readonly=True)
        if keep is not None:
            keep[:] = owned
        if rows is not None and len(rows):
            local = _sum_of_squares(owned[rows])
        del owned
    array = b.array_w
    cpp.set_bc(array, bcs, x.array_r, -1.0)
    del array
    return local, lift


def _assemble_into(array, F, constants, coefficients=None):
    """``array`` = F assembled (zeroed first); the array is given back to PETSc (its state
    raised, as written) when the caller's reference goes. ``coefficients``: F's packed, if
    known."""
    import dolfinx.cpp.fem as cpp

    array.fill(0.0)
    if coefficients is None:
        coefficients = cpp.pack_coefficients(F)
    cpp.assemble_vector(array, F, constants, coefficients)


def _sum_of_squares(v):
    """Σ v², as ``np.sum(v ** 2)`` sums it; a diverging iterate's overflow to inf is quiet
    (the test then says NaN or diverged). ``np.errstate`` only where it can overflow: it
    costs twice the sum."""
    if abs(v).max() < 1e100:  # no square, nor their sum, near the overflow
        return float(np.add.reduce(v * v))
    with np.errstate(over="ignore"):
        return float(np.add.reduce(v * v))


def lifts(bcs, x, rows, targets=None, serial=None):
    """Whether the lifting of ``bcs`` about ``x`` can be nonzero: some constrained dof of
    ``x`` differs from its prescribed value g (or is not finite) on some rank. Each term of
    the lifting is A_ij (g_j - x_j), an exact zero where x_j = g_j: a time step or a load
    step that starts from the prescribed values, and every Newton iterate after the first,
    need none. ``rows``: the owned constrained rows (None: always lift); ``targets``: g on
    them (:func:`prescribed`, or its ``tolist()``), if known; ``serial``: whether ``x`` lives on one rank, if
    known. Collective."""
    if not bcs or rows is None:
        return bool(bcs)
    if targets is None:
        targets = prescribed(bcs, rows, x.getLocalSize())
    values = x.getArray(readonly=True)[rows]
    if isinstance(targets, list):  # as floats: compared without NumPy's dispatch
        local = values.tolist() != targets  # NaN: never equal, lift
    else:
        local = bool((values != targets).any())  # NaN: lift
    if serial is None:
        serial = x.getComm().getSize() == 1
    if serial:
        return local
    from mpi4py import MPI

    return bool(x.getComm().tompi4py().allreduce(local, op=MPI.LOR))


def prescribed(bcs, rows, n_owned):
    """The prescribed values g of ``bcs`` on the owned constrained ``rows`` (local)."""
    from dolfinx.cpp.fem import set_bc

    g = np.empty(n_owned)  # only the constrained rows are written, and read
    set_bc(g, bcs, None, 1.0)
    return g[rows]


def assemble_tangent(A, J, bcs, constants=None, coefficients=None):
    """A = J with identity rows and columns on the constrained dofs (A zeroed first), as
    ``dolfinx.fem.petsc.assemble_matrix`` assembles it, through the C++ calls directly.
    ``constants``: J's constants packed, if the caller knows they have not changed;
    ``coefficients``: J's coefficients packed at this state, if the caller has them."""
    import dolfinx.cpp.fem as cpp
    from petsc4py import PETSc

    A.zeroEntries()
    constants = cpp.pack_constants(J) if constants is None else constants
    if coefficients is None:
        coefficients = cpp.pack_coefficients(J)
    cpp.petsc.assemble_matrix(A, J, constants, coefficients, bcs)
    if J.function_spaces[0] is J.function_spaces[1]:  # square: the conditions' diagonal
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        cpp.petsc.insert_diagonal(A, J.function_spaces[0], bcs, 1.0)
    A.assemble()


def assemble_load(f, F, load_factor, bcs):
    """Load vector f = F(w, 0) - F(w, 1) = -∂F/∂λ at the current w, for F linear in the load factor
    (a ``fem.Constant``), zero on constrained dofs; the load factor is left unchanged."""
    import dolfinx.fem.petsc as fp
    from petsc4py import PETSc

    lam = float(load_factor.value)
    at_one = f.duplicate()
    for vec, value in ((f, 0.0), (at_one, 1.0)):
        load_factor.value = value
        with vec.localForm() as local:
            local.set(0.0)
        fp.assemble_vector(vec, F)
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    f.axpy(-1.0, at_one)
    at_one.destroy()
    fp.set_bc(f, bcs, scale=0.0)
    load_factor.value = lam


def assembler(F, J, bcs):
    """(residual vector, tangent matrix, ``assemble()`` filling both) of the UFL forms F and J
    with the supports ``bcs`` applied to the tangent: the assembly of one Newton iteration."""
    import dolfinx.fem.petsc as fp
    from dolfinx.cpp.fem import pack_constants

    from .forms import compile_form

    F, J = compile_form(F), compile_form(J)
    b, A = fp.create_vector(F), fp.create_matrix(J)

    def assemble():  # as Newton's callbacks assemble (:func:`assemble_residual`)
        with b.localForm() as local:
            _assemble_into(local.array_w, F, pack_constants(F))
        assemble_tangent(A, J, bcs)

    return b, A, assemble


def same_coefficients(F, J):
    """Whether the forms ``F`` and ``J`` take the same coefficients in the same order (the
    same Functions' storage), on the same integrals: their packed coefficients are then the
    same arrays, and one packing serves both at one state."""

    def storage(form):
        return [c.x.array.__array_interface__["data"][0] for c in form.coefficients]

    def integrals(form):
        return [(t, tuple(form.integral_ids(t))) for t in form.integral_types]

    return storage(F) == storage(J) and integrals(F) == integrals(J)
