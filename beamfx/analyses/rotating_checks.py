"""Physical tests of a rotating steady state: whether a failed steady-state solve lost the
steady state (a divergence speed passed: a physical stop) or failed numerically.

Newton failing is not evidence of a physical stop. The test here is the tangent of the
relative equilibrium, K_T(Ω²) (elastic, geometric and spin-softening stiffness): a steady state
exists and is statically stable while K_T is positive definite; at a divergence speed its
lowest eigenvalue μ (of K_T v = μ M v) crosses zero. After a failure the last converged state
of the Ω² ramp, at load factor λ_n, is tested: μ_n ≤ 0, or μ falling from its value at rest
so that its linear extrapolation in Ω² reaches zero by the asked speed (λ ≤ 1), is a loss of
steady state; otherwise the failure is numerical.
"""

import numpy as np

from ..solvers.snes import SolveFailed


class NoSteadyState(SolveFailed):
    """No steady state at the asked speed (a physical stop: a divergence speed passed)."""


def lowest_tangent_eigenvalue(frame, prefix="beamfx_rotating_check_"):
    """μ of K_T v = μ M v nearest 0 about the model's current state and load factor."""
    import dolfinx.fem.petsc as fp

    from ..solvers.eigen import solve_eigen

    K_form, _, M_form = frame.compiled()
    bcs = frame.model.bcs
    K = fp.assemble_matrix(K_form, bcs=bcs, diagonal=1.0)  # constrained rows at μ = ∞
    K.assemble()
    M = fp.assemble_matrix(M_form, bcs=bcs, diagonal=0.0)
    M.assemble()
    try:
        pairs = solve_eigen(K, M, 1, 0.0, prefix, hermitian=False)
    finally:
        for A in (K, M):
            A.destroy()
    for x in pairs.vectors:
        x.destroy()
    return float(pairs.values[0].real)


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
    mu_last = lowest_tangent_eigenvalue(frame)
    frame.set_speed(speed)
    model.reset()
    model.set_load_factor(0.0)
    mu_0 = lowest_tangent_eigenvalue(frame)
    model.w.x.array[:] = saved
    model.w.x.scatter_forward()
    model.set_load_factor(lam_now)
    share = lam_last * (speed_last / speed) ** 2 if speed != 0 else 0.0
    at = f"{np.sqrt(share) * abs(speed):.6g} rad/s"
    numbers = f"lowest tangent eigenvalue {mu_0:.4g} at rest, {mu_last:.4g} at {at}"
    if mu_last <= 0:
        return True, f"the tangent is not positive definite at {at} ({numbers})"
    if share > 0 and mu_last < mu_0:
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
