"""Schwab & Meijaard (2009), problem 2.10: a cantilever on a hub spinning about z.

Flap (out of the rotation plane) and lead-lag (in it) first frequencies in the rotating frame,
divided by the zero-speed clamped-free values 3.516015 sqrt(EI/(ρA L⁴)) (EI_y for flap, EI_z
for lead-lag; see the reference's 'misprint'), at Ω = α ω_Byth. Steady state under the
centrifugal load solved nonlinearly, then (λ² M + λ G + K_T) v = 0
(:mod:`beamfx.analyses.rotating`).

The paper's element is Euler-Bernoulli without bending rotary inertia, so are the models here:
no rotary inertia, and shear made rigid by extrapolation: each setting is solved with the
shear stiffness per plane GA = f (EI/L² + N/10) (:func:`stiff_terms`, N the root tension) at
f = 1e5 and 2e5 (the same compiled forms, the section field changed in place) and the values
extrapolated to 1/f → 0 (the Timoshenko correction is linear in 1/GA: -2.3e-5 on both ratios
at f = 1e5, and what the extrapolation leaves is of the order of its square). The factor
balances that remainder against round-off, which grows with the penalty: measured at alpha = 0
against the exact 1 + 7.4e-8 (the constant 3.516015 is rounded), f = 1e4 leaves -3e-8 (the
squared term), f = 1e5 ±3e-8, f = 1e6 up to 5e-7. A truly shear-rigid penalty
(1e8 EI_z/L², i.e. 1e10 EI_y/L² for flap) costs the flap frequency five digits.

Two cases:

* ``sm210_rotating``: the geometrically exact beam, extensible (EA of the section). Its
  steady state stretches, and the Coriolis forces couple lead-lag with extension.
* ``sm210_rotating_inextensible``: EA = f (EI_z/L² + N/10) (extrapolated like the shear),
  the paper's model (it linearises about the undeformed state with the centrifugal
  pre-stress, without extension).
"""

from dataclasses import replace

import numpy as np

from ..physics import sections
from ..physics.kinematics import Kinematics
from ..spec import Beam, Model, Support
from ._builders import CLAMP, straight
from .registry import reference, register
from .schwab_meijaard_eigen import EigenCase

FILE = "schwab_meijaard_2009.json"
MAT = reference(FILE)["material"]
E, NU, RHO = MAT["E"], MAT["nu"], MAT["rho"]
P210 = reference(FILE, "sm210_rotating_beam")
L210 = P210["geometry"]["L"]
S210 = sections.rectangle(E, E / (2 * (1 + NU)), RHO, P210["section"]["h"], P210["section"]["w"])
BETA2 = 3.516015  # (1.875104)², the clamped-free constant of the reference's 'theory'
OMEGA_BY = BETA2 * np.sqrt(S210.EI_y / (S210.rho_A * L210**4))
OMEGA_BZ = BETA2 * np.sqrt(S210.EI_z / (S210.rho_A * L210**4))
ALPHAS = tuple(P210["alphas"])
#: first axial frequency of the clamped-free rod, (π/2) sqrt(E/ρ)/L: an extensible rod has no
#: steady state beyond Ω = OMEGA_AXIAL (its centrifugal stretch grows without bound)
OMEGA_AXIAL = np.pi / 2 * np.sqrt(E / RHO) / L210
F_STIFF = 1e5  # shear (and, inextensible, axial) stiffness factor, then 2 F_STIFF
SETTINGS = tuple((n, p) for p in (2, 3, 4) for n in (1, 2, 4, 8, 16, 32))


def stiff_terms(f, alpha=0.0):
    """(GA_y, GA_z, EA) of the Euler-Bernoulli limit at Ω = α ω_Byth: f (EI/L² + N/10) for
    each plane, N = ρA Ω² L²/2 the tension at the root. The tension term matters at high
    speed: a Reissner beam in tension N shears with the stiffness GA − N, and the remainder of
    the extrapolation is ~(N/GA)²; with f EI/L² alone it was 1.3e-4 on the flap ratio at
    alpha = 100. N/10 rather than N: GA costs round-off as it grows (1e-6 on the ratios at
    alpha = 100 with f N, 3e-7 with f N/10, whose remainder (10/f)² is 1e-8)."""
    N = S210.rho_A * (alpha * OMEGA_BY) ** 2 * L210**2 / 2
    return (
        f * (S210.EI_z / L210**2 + N / 10),
        f * (S210.EI_y / L210**2 + N / 10),
        f * (S210.EI_z / L210**2 + N / 10),
    )


def blade_model(n, p, f=F_STIFF, extensible=True):
    """SM 2.10's cantilever along x, clamped at the hub (origin), with the shear stiffnesses
    (and, unless ``extensible``, EA) of :func:`stiff_terms` at α = 0: GA_y = f EI_z/L²,
    GA_z = f EI_y/L² (each plane stiff in shear by the same factor), EA = f EI_z/L²."""
    GA_y, GA_z, EA = stiff_terms(f)
    s = replace(S210, GA_y=GA_y, GA_z=GA_z, EA=S210.EA if extensible else EA)
    return Model(
        beams=(Beam("b", straight(L210), s, n, p),),
        supports=(Support("b:start", CLAMP),),
        kinematics=Kinematics(),
    )


def first_flap_and_lead_lag(frame, alpha, n_modes=4):
    """(flap, lead-lag) frequencies (rad/s) at Ω = α ω_Byth: the lowest mode moving out of
    the rotation plane (z) and the lowest moving in it; and the steady state's Newton
    iterations. One load step: the steady stretch of a straight radial beam is linear."""
    from ..analyses.rotating import axis_fraction, solve_rotating_modes, solve_steady

    its = solve_steady(
        frame, alpha * OMEGA_BY, steps=1, prefix="beamfx_bench_rotating_static_"
    ).newton_iterations
    while True:
        r = solve_rotating_modes(frame, n_modes, prefix="beamfx_bench_rotating_")
        out_of_plane = np.array([axis_fraction(frame.model, v, frame.axis) for v in r.vectors])
        flap, lag = r.omega[out_of_plane > 0.5], r.omega[out_of_plane < 0.5]
        if len(flap) and len(lag):
            return flap[0], lag[0], its
        n_modes *= 2


def set_stiff_terms(model, f, alpha, extensible):
    """Put :func:`stiff_terms` into the model's stiffness field (in place: no new forms)."""
    GA_y, GA_z, EA = stiff_terms(f, alpha)
    C = model.discretisation.stiffness.x.array.reshape(-1, 6)
    C[:, 1], C[:, 2] = GA_y, GA_z
    if not extensible:
        C[:, 0] = EA


def rigid_limit_ratios(n, p, extensible, alphas):
    """Flap and lead-lag ratios ("flap alpha=..." and "lead_lag alpha=..." keys) at each alpha,
    extrapolated to the shear-rigid (and unless ``extensible`` inextensible) limit from
    f = F_STIFF and 2 F_STIFF (:func:`stiff_terms`); also the model, its rotating frame and
    the Newton iterations. The formulation is the one a scene would get
    (:func:`~beamfx.analyses.mixed.choose_formulation`: mixed from a stiffness ratio of 1e8)."""
    from ..analyses.mixed import choose_formulation
    from ..analyses.model import BeamModel
    from ..analyses.rotating import RotatingFrame

    spec = blade_model(n, p, F_STIFF, extensible)
    model = BeamModel(replace(spec, formulation=choose_formulation(spec, "rotating")[0]))
    frame = RotatingFrame(model, rotary="none")
    out, its = {}, 0
    for k in (1, 2):
        for alpha in alphas:
            set_stiff_terms(model, k * F_STIFF, alpha, extensible)
            flap, lag, n = first_flap_and_lead_lag(frame, alpha)
            its += n
            for name, value in (("flap", flap / OMEGA_BY), ("lead_lag", lag / OMEGA_BZ)):
                key = f"{name} alpha={alpha:g}"
                out[key] = out.get(key, 0.0) + (2 * value if k == 2 else -value)
    return out, model, frame, its


def _inextensible(n, p):
    values, model, _, its = rigid_limit_ratios(n, p, False, ALPHAS)
    return values, model.unknowns(), its


def _extensible(n, p):
    from ..solvers.snes import SolveFailed

    values, model, frame, its = rigid_limit_ratios(n, p, True, (*ALPHAS[:-1], 50, 70))
    for alpha in (50, 70):  # flap is ~Omega there; the lead-lag columns show the softening
        del values[f"flap alpha={alpha}"]
    try:
        first_flap_and_lead_lag(frame, ALPHAS[-1])
        values["steady_state alpha=100"] = 1.0
    except SolveFailed:
        values["steady_state alpha=100"] = 0.0
    return values, model.unknowns(), its


def _paper(table):
    rows = P210["tables"][table]["rows"]
    return ", ".join(f"{a:g}: {v:.7g}" for a, v in zip(ALPHAS, rows[-1]))


#: for the report's Campbell plot: the ratios' denominators (rad/s) and the paper's BEAM values
CAMPBELL = {
    "omega_By": float(OMEGA_BY),
    "omega_Bz": float(OMEGA_BZ),
    "alphas": list(ALPHAS),
    "paper_flap": list(P210["tables"]["BEAM_flap"]["rows"][-1]),
    "paper_lead_lag": list(P210["tables"]["BEAM_lead_lag"]["rows"][-1]),
}

NOTE_COMMON = (
    "Euler-Bernoulli limit: shear (and for the inextensible case extension) extrapolated to "
    "rigid from GA = f (EI/L^2 + N/10), f = 1e5 and 2e5, N the root tension; no rotary "
    "inertia; consistent mass; steady state by "
    "Newton, then the quadratic eigenproblem with the gyroscopic matrix. Paper, BEAM with 32 "
    f"elements (not converged at high alpha): flap {_paper('BEAM_flap')}; lead-lag "
    f"{_paper('BEAM_lead_lag')}. Southwell's first-order relation for the first mode of a "
    "uniform cantilever: flap omega^2 = omega_0^2 + K_s Omega^2, lead-lag omega^2 = "
    "omega_0^2 + (K_s - 1) Omega^2 with K_s = 1.19334 (the exact perturbation integral "
    "int (L^2 - X^2)/2 phi'^2 / int phi^2)."
)

register(
    EigenCase(
        "sm210_rotating_inextensible",
        "Schwab & Meijaard 2009, 2.10",
        "Rotating cantilever, the paper's model (inextensible): flap and lead-lag ratios",
        _inextensible,
        lambda values: values,
        None,
        1e-6,
        SETTINGS,
        extra={"campbell": CAMPBELL},
        note=NOTE_COMMON
        + " Inextensible, which is the paper's model (pre-stress about the undeformed state): "
        "its converged values are what the paper's BEAM columns tend to at every alpha, 100 "
        "included. No instability at any mesh: the tension stiffness and the spin softening "
        "are both second derivatives of one discrete potential (strain energy plus centrifugal "
        "potential) at a discrete equilibrium, so they balance exactly where they must (a rigid "
        "rotation about the spin axis costs nothing; a blade hinged at the axis flaps at exactly "
        "Omega on any mesh), the tip element included, where the normal force vanishes.",
    )
)

register(
    EigenCase(
        "sm210_rotating",
        "Schwab & Meijaard 2009, 2.10",
        "Rotating cantilever, geometrically exact (extensible): flap and lead-lag ratios",
        _extensible,
        lambda values: values,
        None,
        1e-6,
        SETTINGS,
        extra={"campbell": CAMPBELL},
        note=NOTE_COMMON
        + " Extensible, geometrically exact: the flap ratios agree with the inextensible model "
        "to O(rho Omega^2 L^2/E) (1e-4 at alpha = 1); lead-lag does not: the Coriolis forces "
        "couple it with extension (-4 (rho omega_0^2 L^2/E) int phi psi / int phi^2 in the "
        "Southwell coefficient, psi'' + (rho omega_0^2/E) psi = -phi), and the stretched "
        "beam bends more easily per unit reference length; for this beam (in-plane omega_0 "
        "an eighth of the first axial frequency) the lead-lag coefficient nearly halves "
        "(tests/convergence/test_rotating.py checks it against that perturbation formula). At high speed the extension decides: the steady stretch of a "
        "linear-elastic rod, x'' + (rho Omega^2/E) x = 0, grows without bound as Omega "
        "approaches the first axial frequency (pi/2) sqrt(E/rho)/L, alpha = "
        f"{OMEGA_AXIAL / OMEGA_BY:.2f}, while the lead-lag frequency falls to zero (columns "
        "alpha=50, 70). At alpha = 100 there is no steady state (steady_state alpha=100 = 0: "
        "Newton lands on a folded, unstable solution, which is rejected). So our model has no "
        "spurious tip instability, but a real divergence of the extensible rod before alpha = "
        "100; at alpha = 10 the centrifugal stress at the root, rho Omega^2 L^2/2 = "
        f"{RHO * (10 * OMEGA_BY) ** 2 * L210**2 / 2 / 1e9:.1f} GPa, is already far beyond any "
        "steel.",
    )
)
