"""Functions of one variable written in a scene: a number, an expression string or a table.

``"0.02 * (1 - 0.5 * s / L)"`` (names: the variable, the constants given by the caller, pi and
e, and the functions below; comparisons give 0 or 1, and ``where(t < 15, a, b)`` picks) or ``{ s = [0, 1], values = [0.02, 0.01] }`` (piecewise linear,
constant beyond the ends). Expressions are checked with :mod:`ast` before use: only
arithmetic, calls of the listed functions and the listed names are allowed.

Bounded by construction, so a hostile scene cannot hang or exhaust ``check``: the text has at
most :data:`MAX_LENGTH` characters, the tree at most :data:`MAX_NODES` nodes and depth
:data:`MAX_DEPTH`, and every number is a float (``10**10**10`` is then a float power that
overflows at once instead of a Python integer of 10¹⁰ digits); each node is one NumPy
operation on the sample points. Results that are not finite are reported by the callers.
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
MAX_LENGTH = 2000  # characters of an expression
MAX_NODES = 400  # nodes of its syntax tree
MAX_DEPTH = 40  # nesting of its syntax tree
_NODES = (
    ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load, ast.Constant,
    ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd, ast.Mod,
    ast.Compare, ast.Lt, ast.LtE, ast.Gt, ast.GtE,
)  # fmt: skip


def _quote(text, limit=60):
    """The expression as quoted in messages, cut to ``limit`` characters."""
    return repr(text) if len(text) <= limit else repr(text[: limit - 3] + "...")


def _parse(text):
    """The syntax tree of ``text``, within the size limits."""
    if not isinstance(text, str):
        raise ValueError(f"expected an expression string, got {type(text).__name__}")  # noqa: TRY004
    if len(text) > MAX_LENGTH:
        raise ValueError(f"an expression of {len(text)} characters; at most {MAX_LENGTH}")
    # the parser's own nesting limit (about 200 parentheses) raises SyntaxError or, in some
    # versions, RecursionError/MemoryError: all are a bad expression
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as e:
        raise ValueError(f"{_quote(text)} is not an expression: {e.msg}") from None
    except (RecursionError, MemoryError):
        raise ValueError(f"{_quote(text)}: nested too deeply") from None
    nodes = list(ast.walk(tree))
    if len(nodes) > MAX_NODES:
        raise ValueError(f"an expression of {len(nodes)} syntax nodes; at most {MAX_NODES}")
    if _depth(tree) > MAX_DEPTH:
        raise ValueError(f"an expression nested deeper than {MAX_DEPTH} levels")
    return tree, nodes


def _depth(tree):
    """Depth of a syntax tree, without recursion."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest


def _check_node(node, text, allowed):
    if not isinstance(node, _NODES):
        message = f"{_quote(text)}: {type(node).__name__} is not allowed in an expression"
        raise ValueError(message)  # noqa: TRY004 (bad scene input, not a type error)
    if isinstance(node, ast.Name) and node.id not in allowed:
        raise ValueError(f"{_quote(text)}: unknown name {node.id!r}; allowed: {allowed}")
    if isinstance(node, ast.Call) and not (
        isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS and not node.keywords
    ):
        raise ValueError(f"{_quote(text)}: only these functions may be called: {sorted(FUNCTIONS)}")
    if isinstance(node, ast.Constant):
        if not isinstance(node.value, int | float) or isinstance(node.value, bool):
            raise ValueError(f"{_quote(text)}: {node.value!r} is not a number")  # noqa: TRY004
        try:
            node.value = float(node.value)  # float arithmetic: bounded time, overflow -> error
        except OverflowError:
            raise ValueError(f"{_quote(text)}: the number {node.value} is too large") from None


class _IgnoreAll:
    """``np.errstate(all="ignore")`` through NumPy 1's error object directly: the same mask
    (every floating-point error ignored) at a tenth of the cost, for a history evaluated at
    one time per step. One object per use (NumPy's error object is per thread)."""

    __slots__ = ("saved",)

    def __enter__(self):
        self.saved = old = _GETERROBJ()
        _SETERROBJ([old[0], 0, old[2]])  # buffer size and callback kept; mask 0: ignore all

    def __exit__(self, *exc):
        _SETERROBJ(self.saved)


_GETERROBJ = getattr(np, "geterrobj", None)  # NumPy 1 only
_SETERROBJ = getattr(np, "seterrobj", None)


def _ignoring_errors(ndim):
    """A context that ignores floating-point errors: the cheap one for a single value."""
    if ndim or _SETERROBJ is None:
        return np.errstate(all="ignore")
    return _IgnoreAll()


def compile_expression(text, variable, constants=None):
    """A vectorised function of ``variable`` from an expression string.

    Raises:
        ValueError: naming the offending part and the allowed names or limits.
    """
    names = {**CONSTANTS, **(constants or {})}
    allowed = sorted([variable, *names, *FUNCTIONS])
    tree, nodes = _parse(text)
    for node in nodes:
        _check_node(node, text, allowed)
    scope = {"__builtins__": {}, **names, **FUNCTIONS}
    fn = eval(compile(_as_lambda(tree, variable), "<scene expression>", "eval"), scope)

    def f(x):
        x = np.asarray(x, float)
        try:
            with _ignoring_errors(x.ndim):  # non-finite results are the caller's to report
                y = fn(x)
        except (OverflowError, ZeroDivisionError) as e:  # float arithmetic of constants
            raise ValueError(f"{_quote(text)}: {e}") from None
        if not x.ndim:  # one value (a history at a time step): the same 0-d array, cheaper
            return np.array(y, dtype=float)
        return np.broadcast_to(y, x.shape).astype(float)

    def at(x):
        """``float(f(x))`` of one number ``x``: the same operations (on a 0-d array)."""
        try:
            with _ignoring_errors(0):
                return float(fn(np.asarray(x, float)))
        except (OverflowError, ZeroDivisionError) as e:
            raise ValueError(f"{_quote(text)}: {e}") from None

    f.text, f.at = text, at
    return f


def _as_lambda(tree, variable):
    """The checked expression ``tree`` as the syntax tree of ``lambda variable: tree``:
    compiled once into a function, whose variable is a local and whose names are the scope's
    (the same operations as evaluating the tree with the variable bound, a few microseconds
    less per call: a history is evaluated at every time step)."""
    args = ast.arguments(
        posonlyargs=[], args=[ast.arg(arg=variable)], kwonlyargs=[], kw_defaults=[], defaults=[]
    )
    return ast.fix_missing_locations(ast.Expression(body=ast.Lambda(args=args, body=tree.body)))


def table_function(xs, values):
    """Piecewise linear interpolation of a table (constant beyond its ends)."""
    xs, values = np.asarray(xs, float), np.asarray(values, float)
    if not (np.all(np.isfinite(xs)) and np.all(np.isfinite(values))):
        raise ValueError("a table's abscissae and values must be finite numbers")
    if len(xs) < 2 or len(xs) != len(values) or not np.all(np.diff(xs) > 0):
        raise ValueError(
            "a table needs at least two increasing abscissae and as many values "
            f"(got {len(xs)} abscissae, {len(values)} values)"
        )

    def f(x):
        return np.interp(np.asarray(x, float), xs, values)

    return f
