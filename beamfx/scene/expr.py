"""Functions of one variable written in a scene: a number, an expression string or a table.

``"0.02 * (1 - 0.5 * s / L)"`` (names: the variable, the constants given by the caller, pi and
e, and the functions below; comparisons give 0 or 1, and ``where(t < 15, a, b)`` picks) or ``{ s = [0, 1], values = [0.02, 0.01] }`` (piecewise linear,
constant beyond the ends). Expressions are checked with :mod:`ast` before use: only
arithmetic, calls of the listed functions and the listed names are allowed.
"""

import ast
import math

import numpy as np

FUNCTIONS = {
    name: getattr(np, name)
    for name in ("sin", "cos", "tan", "exp", "log", "sqrt", "abs", "arctan", "tanh", "cosh", "sinh")
}
FUNCTIONS.update(min=np.minimum, max=np.maximum, where=np.where)
CONSTANTS = {"pi": math.pi, "e": math.e}
_NODES = (
    ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load, ast.Constant,
    ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd, ast.Mod,
    ast.Compare, ast.Lt, ast.LtE, ast.Gt, ast.GtE,
)  # fmt: skip


def compile_expression(text, variable, constants=None):
    """A vectorised function of ``variable`` from an expression string.

    Raises:
        ValueError: naming the offending part and the allowed names.
    """
    names = {**CONSTANTS, **(constants or {})}
    allowed = sorted([variable, *names, *FUNCTIONS])
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as e:
        raise ValueError(f"{text!r} is not an expression: {e.msg}") from None
    for node in ast.walk(tree):
        if not isinstance(node, _NODES):
            message = f"{text!r}: {type(node).__name__} is not allowed in an expression"
            raise ValueError(message)  # noqa: TRY004 (bad scene input, not a type error)
        if isinstance(node, ast.Name) and node.id not in allowed:
            raise ValueError(f"{text!r}: unknown name {node.id!r}; allowed: {allowed}")
        if isinstance(node, ast.Call) and not (
            isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
        ):
            raise ValueError(f"{text!r}: only these functions may be called: {sorted(FUNCTIONS)}")
    code = compile(tree, "<scene expression>", "eval")
    scope = {"__builtins__": {}, **names, **FUNCTIONS}

    def f(x):
        x = np.asarray(x, float)
        return np.broadcast_to(eval(code, scope, {variable: x}), x.shape).astype(float)

    f.text = text
    return f


def table_function(xs, values):
    """Piecewise linear interpolation of a table (constant beyond its ends)."""
    xs, values = np.asarray(xs, float), np.asarray(values, float)
    if len(xs) < 2 or len(xs) != len(values) or np.any(np.diff(xs) <= 0):
        raise ValueError(
            "a table needs at least two increasing abscissae and as many values "
            f"(got {len(xs)} abscissae, {len(values)} values)"
        )

    def f(x):
        return np.interp(np.asarray(x, float), xs, values)

    return f
