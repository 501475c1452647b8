"""Benchmark registry: one module per paper; each case = model builder + reference + metric.

``beamfx bench`` runs every case over its convergence settings and reports, per setting, the
unknowns, elements × degree, Newton iterations, wall time cold (first JIT) and warm, and the
error against the reference.
"""

from .registry import HERE, REGISTRY, Case, reference, register

__all__ = ["HERE", "REGISTRY", "Case", "all_cases", "reference", "register"]


def all_cases():
    """Import every paper module (they register their cases) and return the registry."""
    from . import (  # noqa: F401
        adaptive_bend45,
        beamdyn_static,
        blade_prebend,
        classic,
        coupled_cantilever,
        howcroft_2016,
        lattice_buckling,
        nrel5mw_blade,
        pai_beam,
        pai_rotating,
        pai_spin_ramp,
        planar_rollup,
        schwab_meijaard_2009,
        schwab_meijaard_eigen,
        schwab_meijaard_rotating,
        schwab_meijaard_torque,
        shallow_arch,
        shallow_arch_bifurcation,
        star_dome,
        transient,
    )

    return REGISTRY
