"""Self-checks of the independent rod-equation reference (exact roll-up, elastica, cross-checks)."""

from rod_equations import (  # noqa: F401  (pytest collects them here)
    test_arc_curve_frame,
    test_bathe_bolourchi_45_bend,
    test_elastica_exact_vs_table,
    test_follower_cantilever_exact,
    test_mattiasson_shooting,
    test_pure_moment_helix_exact,
    test_rollup_circle,
    test_rotation_utilities,
    test_schwab_meijaard_runs,
    test_shooting_pure_moment_matches_pure_end_moments,
)
