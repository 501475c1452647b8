r"""The modes nearest a target frequency in Hz, from a solver that finds those nearest in ω².

Shift-and-invert at σ = ω_t² finds the eigenvalues nearest in ω²; as
|ω² − ω_t²| = |ω − ω_t| (ω + ω_t), that favours the modes below the target (at 100 Hz the
four nearest in ω² were 104.5, 52.3, 16.7 and 8.35 Hz, while 146.4 Hz is nearer than 52.3 Hz).
So more pairs are asked for, and the ``n`` nearest in |f − f_t| kept, once the pairs found
provably hold them: a mode within d of the target in frequency lies within
2π d (2 ω_t + 2π d) of it in ω² (also for ω² < 0, shown with ω < 0), so when the pairs found
reach that far in ω², none nearer in Hz is missing. Otherwise twice as many are asked for, up
to the model's finite eigenvalues (:mod:`.mode_count`), where the answer is exact.
"""

import numpy as np

#: pairs asked for beyond the ``n`` wanted in the first solve: n + max(EXTRA, n)
EXTRA = 4


def nearest_in_hz(hz, lam, n, target_hz):
    """(indices of the ``n`` frequencies ``hz`` nearest ``target_hz``, nearest first, whether
    the pairs found prove them the nearest of all): ``lam`` are their ω² (1/s²)."""
    hz, lam = np.asarray(hz, float), np.asarray(lam, float)
    d = np.abs(hz - target_hz)
    keep = np.argsort(d, kind="stable")[:n]
    if len(keep) < n:
        return keep, False
    reach = 2 * np.pi * d[keep[-1]]
    omega_t = 2 * np.pi * target_hz
    needed = reach * (2 * omega_t + reach)  # in ω²: any mode nearer in Hz lies within it
    found = np.max(np.abs(lam - omega_t**2), initial=0.0)
    return keep, bool(found > needed)


def solve_nearest_hz(solve, n, target_hz, most):
    """The :class:`~.modal.ModalResult` of the ``n`` modes nearest ``target_hz`` in Hz, nearest
    first. ``solve(m)``: the ``m`` modes nearest in ω² (a ModalResult); ``most``: the finite
    eigenvalues there are (asking for all of them is exact)."""
    from ..solvers import SolveFailed

    m, spent = min(n + max(EXTRA, n), most), {}
    while True:
        try:
            res = solve(m)
        except SolveFailed as e:  # fewer finite eigenvalues than the count (an upper bound)
            found = (getattr(e, "details", None) or {}).get("converged", 0)
            if m == n or not n <= found < m:
                raise
            m = most = found  # all there are: asking for them is exact
            continue
        for key, value in res.seconds.items():  # every try's time counts
            spent[key] = spent.get(key, 0.0) + value
        keep, proven = nearest_in_hz(res.hz, res.eigenvalues, n, target_hz)
        if proven or m >= most:
            break
        m = min(2 * m, most)
    return res._replace(
        seconds=spent,
        eigenvalues=res.eigenvalues[keep],
        omega=res.omega[keep],
        hz=res.hz[keep],
        modes=tuple(res.modes[i] for i in keep),
        residuals=res.residuals[keep],
    )


__all__ = ["nearest_in_hz", "solve_nearest_hz"]
