"""Physical tests of a rotating steady state: whether a failed steady-state solve lost the
steady state (a divergence speed passed: a physical stop) or failed numerically.

Newton failing is not evidence of a physical stop. The test here is the tangent of the
relative equilibrium, K_T(Ω²) (elastic, geometric and spin-softening stiffness): a steady state
exists and is statically stable while K_T is positive definite; at a divergence speed its
lowest eigenvalue μ (of K_T v = μ M v) crosses zero. After a failure the last converged state
of the Ω² ramp, at load factor λ_n, is tested: μ_n ≤ 0, or μ falling from its value at rest
so that its linear extrapolation in Ω² reaches zero by the asked speed (λ ≤ 1), is a loss of
steady state; otherwise the failure is numerical.

Each μ is compared with its round-off, :func:`eigenvalue_floor`: a μ ≤ 0 within it is not
resolved from 0 (the displacement form at EA, GA ×1e8 gave μ = −4.32 at rest for the Pai
strip, 8 × P3, whose lowest μ there is 114.88 s⁻²), and the fall from rest counts only where
it exceeds the round-off of both values. The mixed formulation's tangent does not grow with EA, GA, so
its floor stays small (its force unknowns, without mass, are kept out of the eigen solve:
:mod:`beamfx.solvers.eigen_shell`).
"""

import numpy as np

from ..solvers.snes import SolveFailed

#: how many times ε |v|ᵀ|K||v| / |vᴴMv| an eigenvalue's round-off is taken to be. That
#: estimate alone exceeds the observed error: the Pai strip (8 × P3, at rest) in the
#: displacement form at EA, GA ×1e4 gives μ 0.038 away from the mixed form's 114.8775
#: (estimate 6.1), at ×1e8 −4.32 (119 off; estimate 6.2e3); ten times it keeps a margin for
#: the assembly's sums and the factorisation's growth on other models
ROUNDOFF_FACTOR = 10.0


class NoSteadyState(SolveFailed):
    """No steady state at the asked speed (a physical stop: a divergence speed passed)."""


def eigenvalue_floor(K, M, v):
    """Round-off of the eigenvalue μ of K v = μ M v with the (complex, local) eigenvector
    ``v``: :data:`ROUNDOFF_FACTOR` ε |v|ᵀ|K||v| / |vᴴ M v| (first-order perturbation of μ by
    an entrywise relative error ε of K; |K| its entries in absolute value). Collective."""
    from ..solvers.eigen_shell import complex_mult

    comm = K.getComm().tompi4py()
    rows, cols, vals = K.getValuesCSR()
    A = K.duplicate(copy=True)
    A.setValuesCSR(rows, cols, np.abs(vals))
    A.assemble()
    x, y = K.createVecs()
    x.array[:] = np.abs(v)
    A.mult(x, y)
    top = comm.allreduce(float(np.dot(np.abs(v), y.getArray())))
    Mv = complex_mult(M, v, x, y)
    bottom = abs(comm.allreduce(complex(np.vdot(v, Mv))))
    for obj in (A, x, y):
        obj.destroy()
    return ROUNDOFF_FACTOR * np.finfo(float).eps * top / bottom if bottom > 0 else np.inf


def lowest_tangent_eigenvalue(frame, prefix="beamfx_rotating_check_"):
    """(μ, its round-off :func:`eigenvalue_floor`) of K_T v = μ M v nearest 0 about the model's
    current state and load factor."""
    import dolfinx.fem.petsc as fp

    from ..solvers.eigen import solve_eigen
    from ..solvers.eigen_shell import solve_eigen_massless
    from .mixed import owned_force_dofs

    K_form, _, M_form = frame.compiled()
    bcs = frame.model.bcs
    K = fp.assemble_matrix(K_form, bcs=bcs, diagonal=1.0)  # constrained rows at μ = ∞
    K.assemble()
    M = fp.assemble_matrix(M_form, bcs=bcs, diagonal=0.0)
    M.assemble()
    massless = owned_force_dofs(frame.model)
    try:
        if massless is None:
            pairs = solve_eigen(K, M, 1, 0.0, prefix, hermitian=False)
            v = pairs.vectors[0].getArray().astype(complex)
            for x in pairs.vectors:
                x.destroy()
        else:
            pairs = solve_eigen_massless(K, M, 1, prefix, massless)
            v = pairs.vectors[0]
        floor = eigenvalue_floor(K, M, v)
    finally:
        for A in (K, M):
            A.destroy()
    return float(pairs.values[0].real), floor


def steady_state_lost(frame, lam_last, speed_last=None):
    """(lost, why) after a failed solve of the steady state at the frame's speed Ω whose last
    converged state (the model holds it) is at load factor ``lam_last`` and speed
    ``speed_last`` (default Ω: the ramp from rest; a continuation from a previous speed has
    load factor 1). μ is extrapolated in the share of Ω² reached, lam_last·(speed_last/Ω)².
    The model and the frame are left as they were."""
    model, speed = frame.model, frame.speed
    speed_last = speed if speed_last is None else speed_last
    saved, lam_now = model.w.x.array.copy(), float(model.load_factor.value)
    frame.set_speed(speed_last)
    model.set_load_factor(lam_last)
    mu_last, floor_last = lowest_tangent_eigenvalue(frame)
    frame.set_speed(speed)
    model.reset()
    model.set_load_factor(0.0)
    mu_0, floor_0 = lowest_tangent_eigenvalue(frame)
    model.w.x.array[:] = saved
    model.w.x.scatter_forward()
    model.set_load_factor(lam_now)
    share = lam_last * (speed_last / speed) ** 2 if speed != 0 else 0.0
    at = f"{np.sqrt(share) * abs(speed):.6g} rad/s"
    numbers = (
        f"lowest tangent eigenvalue {mu_0:.4g} ± {floor_0:.2g} at rest, "
        f"{mu_last:.4g} ± {floor_last:.2g} at {at} (± its round-off)"
    )
    if abs(mu_last) <= floor_last:
        return False, f"the tangent's lowest eigenvalue is within its round-off ({numbers})"
    if mu_last < 0:
        return True, f"the tangent is not positive definite at {at} ({numbers})"
    if share > 0 and mu_0 - mu_last > floor_0 + floor_last:
        lam_zero = share * mu_0 / (mu_0 - mu_last)
        if lam_zero <= 1.0:
            return True, (
                f"the tangent loses definiteness near {np.sqrt(lam_zero) * abs(speed):.6g} "
                f"rad/s, below the asked speed ({numbers}; extrapolated in Ω²)"
            )
    return False, f"the tangent stays positive definite ({numbers})"


def speed_of_failure(frame, error):
    """(load factor, speed) of the last converged state of a failed steady-state solve: that
    of a continuation (loads at full, ``details["speed_rad_s"]``:
    :func:`~beamfx.analyses.rotating_path.continue_steady`), else of the ramp from the
    undeformed state at the frame's speed."""
    details = getattr(error, "details", None) or {}
    if "speed_rad_s" in details:
        return 1.0, float(details["speed_rad_s"])
    steps = getattr(error, "history", ())
    return (steps[-1].load_factor if steps else 0.0), frame.speed


def classify_failure(frame, error):
    """The exception to raise for a failed steady state at the frame's speed: a
    :class:`NoSteadyState` if :func:`steady_state_lost`, else ``error`` (a numerical failure)
    with the tangent's verdict added to its message and details."""
    steps = getattr(error, "history", ())
    lost, why = steady_state_lost(frame, *speed_of_failure(frame, error))
    speed = f"{frame.speed:.6g} rad/s"
    if lost:
        return NoSteadyState(f"no steady state at {speed}: {why}", steps, "no steady state")
    first, _, rest = str(error).partition("\n")
    return SolveFailed(
        f"numerical failure of the steady state at {speed} ({why}): {first}"
        + (f"\n{rest}" if rest else ""),
        steps,
        getattr(error, "cause", None),
        getattr(error, "remedy", None),
        {**getattr(error, "details", {}), "tangent": why},
    )
