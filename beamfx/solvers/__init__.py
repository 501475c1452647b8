"""Thin PETSc/SLEPc solvers over UFL forms. Knows nothing of beams."""

from .forms import compile_form
from .snes import NewtonSolver, SolveFailed, SolveReport
from .stepping import LoadStep, step_load

__all__ = ["LoadStep", "NewtonSolver", "SolveFailed", "SolveReport", "compile_form", "step_load"]
