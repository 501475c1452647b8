r"""Implicit time integrators for second-order systems M(q) q̈ + f(q, q̇, t) = 0.

The generalized-α method of Chung & Hulbert (1993) in the form of Arnold & Brüls (2007): the
equations of motion hold exactly at :math:`t_{n+1}`, and an auxiliary acceleration ``a``
carries the α-weighting,

.. math::
   (1-α_m)\,a_{n+1} + α_m a_n &= (1-α_f)\,\ddot q_{n+1} + α_f \ddot q_n \\
   q_{n+1} &= q_n + h\dot q_n + h^2(½-β)\,a_n + h^2 β\,a_{n+1} \\
   \dot q_{n+1} &= \dot q_n + h(1-γ)\,a_n + hγ\,a_{n+1}

For linear problems it is the Chung–Hulbert method; in this form nonlinear forces need no
interpolation between time levels, and massless (algebraic) unknowns are solved at t_{n+1}.
Newton's unknown is :math:`q_{n+1}`; the other quantities are affine in it, so the residual
is a transformation of the equations of motion and its Jacobian follows by differentiation.

:func:`richardson` combines results at h and h/2 to cancel the h² error term (the scheme
``"extrapolated"``, :mod:`beamfx.analyses.extrapolation`).

Knows nothing of beams: arrays are NumPy arrays, expressions UFL.
"""

from typing import NamedTuple


class AlphaParameters(NamedTuple):
    """The parameters (α_m, α_f, β, γ) of a generalized-α family scheme, and its name."""

    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float
    name: str


def generalized_alpha(rho_inf):
    """Chung–Hulbert parameters with spectral radius ``rho_inf`` ∈ [0, 1] at h ω → ∞.

    ρ∞ = 1: no numerical damping (the trapezoidal rule); ρ∞ = 0: asymptotic annihilation.
    Second-order accurate for every ρ∞.
    """
    if not 0.0 <= rho_inf <= 1.0:
        raise ValueError(f"rho_inf must lie in [0, 1], got {rho_inf}")
    am = (2 * rho_inf - 1) / (rho_inf + 1)
    af = rho_inf / (rho_inf + 1)
    gamma = 0.5 + af - am
    return AlphaParameters(am, af, 0.25 * (gamma + 0.5) ** 2, gamma, f"generalized-α ρ∞={rho_inf}")


def hht(alpha):
    """Hilber–Hughes–Taylor: α_m = 0 and α_f = α ∈ [0, 1/3] (α = 0 is the trapezoidal rule);
    its spectral radius at infinity is (1 − α)/(1 + α)."""
    if not 0.0 <= alpha <= 1.0 / 3.0:
        raise ValueError(f"HHT alpha must lie in [0, 1/3], got {alpha}")
    gamma = 0.5 + alpha
    return AlphaParameters(0.0, alpha, 0.25 * (1 + alpha) ** 2, gamma, f"HHT α={alpha}")


def newmark(beta=0.25, gamma=0.5):
    """Newmark's method (α_m = α_f = 0); second order only for γ = ½."""
    return AlphaParameters(0.0, 0.0, beta, gamma, f"Newmark β={beta} γ={gamma}")


class AlphaStep:
    """The relations of one step, as UFL expressions of the unknown q_{n+1} (for the residual)
    and as array updates (after convergence).

    Args:
        params: :class:`AlphaParameters`.
        h: the step size as a UFL constant (changing it recompiles nothing).
        constants: the parameters as UFL constants (same names), used in the expressions so
            that another ρ∞ recompiles nothing either; ``params`` if None.
    """

    def __init__(self, params, h, constants=None):
        self.p, self.h, self.c = params, h, constants or params

    def _step(self, q, q_n, v_n, a_n, qdd_n, h, p):
        """(a_{n+1}, q̇_{n+1}, q̈_{n+1}) from q_{n+1} = ``q``, parameters ``p``."""
        a = (q - q_n - h * v_n - h**2 * (0.5 - p.beta) * a_n) / (p.beta * h**2)
        v = v_n + h * (1 - p.gamma) * a_n + h * p.gamma * a
        qdd = ((1 - p.alpha_m) * a + p.alpha_m * a_n - p.alpha_f * qdd_n) / (1 - p.alpha_f)
        return a, v, qdd

    def rates(self, q, q_n, v_n, a_n, qdd_n):
        """(q̇_{n+1}, q̈_{n+1}) as UFL expressions of q_{n+1} = ``q`` (the constants ``h`` and
        parameters, so that a new step size or ρ∞ recompiles nothing)."""
        return self._step(q, q_n, v_n, a_n, qdd_n, self.h, self.c)[1:]

    def advance(self, q, q_n, v_n, a_n, qdd_n, h):
        """New (v, a, q̈) arrays at t_{n+1} for the converged q_{n+1} = ``q`` (step ``h``)."""
        a, v, qdd = self._step(q, q_n, v_n, a_n, qdd_n, h, self.p)
        return v, a, qdd

    def predict(self, q_n, v_n, a_n, h):
        """Starting guess for q_{n+1}: the step with a_{n+1} = a_n."""
        return q_n + h * v_n + h**2 * 0.5 * a_n


def richardson(coarse, fine, order=2):
    r"""Richardson's combination of a result at step h (``coarse``) and at h/2 (``fine``):
    :math:`u_{h/2} + (u_{h/2} - u_h)/(2^p - 1)`, which cancels an error term
    :math:`C h^p` (p = ``order``; p = 2: 4/3 u_{h/2} − 1/3 u_h). Arrays or numbers."""
    return fine + (fine - coarse) / (2**order - 1)
