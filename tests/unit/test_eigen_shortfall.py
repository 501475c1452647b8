"""A shortfall of eigenpairs is accepted (``least``) only when SLEPc ended converged: after a
divergence (iteration limit, breakdown) it is a numerical failure, never a result."""

import numpy as np
import pytest
from petsc4py import PETSc
from slepc4py import SLEPc

from beamfx.solvers import SolveFailed
from beamfx.solvers.eigen import solve_and_collect


class _Solver:
    """An EPS stand-in that converged ``n`` pairs (1, 2, ...) and ended with ``reason``."""

    ConvergedReason = SLEPc.EPS.ConvergedReason

    def __init__(self, n, reason):
        self.n, self.reason = n, reason

    def solve(self):
        pass

    def getConverged(self):
        return self.n

    def getConvergedReason(self):
        return self.reason

    def getEigenvalue(self, i):
        return float(i + 1)

    def getEigenpair(self, i, vr, vi):
        vr.set(1.0)
        return float(i + 1)

    def computeError(self, i):
        return 1e-14

    def getIterationNumber(self):
        return 3

    def destroy(self):
        pass


def _matrix():
    A = PETSc.Mat().createAIJ([4, 4], comm=PETSc.COMM_SELF)
    A.setUp()
    A.assemble()
    return A


def test_fewer_pairs_after_convergence_are_all_there_are():
    A = _matrix()
    values, vectors, _, _ = solve_and_collect(
        _Solver(2, SLEPc.EPS.ConvergedReason.CONVERGED_TOL), A, 4, "t_", lambda vr, vi: 0, least=0
    )
    assert np.allclose(values, [1.0, 2.0]) and len(vectors) == 2


@pytest.mark.parametrize("reason", ["DIVERGED_ITS", "DIVERGED_BREAKDOWN"])
def test_fewer_pairs_after_a_divergence_fail(reason):
    code = getattr(SLEPc.EPS.ConvergedReason, reason)
    with pytest.raises(SolveFailed, match=f"2 of 4 eigenpairs .*SLEPc {reason}"):
        solve_and_collect(_Solver(2, code), _matrix(), 4, "t_", lambda vr, vi: 0, least=0)


def test_all_pairs_found_pass_whatever_the_reason():
    """(a solve that converged every pair asked before its limit is a result)"""
    code = SLEPc.EPS.ConvergedReason.DIVERGED_ITS
    values, _, _, _ = solve_and_collect(_Solver(4, code), _matrix(), 4, "t_", lambda vr, vi: 0)
    assert len(values) == 4
