"""An allow-list scan of a gmsh ``.geo`` script before gmsh interprets it.

gmsh's ``.geo`` language can run programs (``SystemCall``, ``NonBlockingSystemCall``,
``OnelabRun``), write files (``Save``, ``Print``, ``Printf(...) > "file"``, ``CreateDir``),
read other files (``Include``, ``Merge``), wait (``Sleep``), ask the terminal (``GetValue``)
and loop (``For``, ``Macro``/``Call``). A centre line needs none of that, so a ``.geo`` file is
accepted only if every word in it is one of :data:`WORDS` (geometry statements, mathematical
functions), an option of ``Geometry.`` or ``Mesh.``, or a variable the file assigned before
(``r = 0.5;``) whose name starts with a lower-case letter (gmsh's commands start with a
capital, and gmsh goes on after a syntax error: ``SystemCall = 1;`` followed by
``SystemCall "..."`` runs the command). Without loops or branches gmsh reads every statement
once, in order, so the file's size bounds gmsh's work.
"""

import re

#: the words a .geo centre line may use (gmsh 4.x); everything else is refused
WORDS = frozenset(
    """
    Point Line Circle Ellipse Spline BSpline Bezier Curve Loop Wire Compound Physical
    Surface Plane Ruled Volume Transfinite Characteristic Length Recombine SetFactory
    Coherence Extrude Rotate Translate Symmetry Dilate Duplicata Boundary CombinedBoundary
    PointsOf Layers Using Progression Bump Sin Cos Tan Asin Acos Atan Atan2 Sinh Cosh Tanh
    Exp Log Log10 Sqrt Fabs Abs Floor Ceil Round Fmod Modulo Hypot Min Max Pi
    newp newl newc news newv newll newsl newreg newcl
    """.split()  # noqa: SIM905 (a word list reads better as text)
)
#: a variable's name starts with a lower-case letter: gmsh's commands start with a capital, and
#: gmsh goes on after a syntax error, so ``SystemCall = 1;`` must not make a command a variable
_VARIABLE = re.compile(r"[a-z][A-Za-z0-9_]*")
#: option families a .geo file may set (``General.``, ``Solver.``, ``Print.``, ... may not)
OPTION_FAMILIES = ("Geometry", "Mesh")

_TOKEN = re.compile(
    r"""(?P<space>\s+)
      | (?P<comment>//[^\n]*|/\*.*?\*/)
      | (?P<string>"(?:\\.|[^"\\\n])*")
      | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
      | (?P<word>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)
      | (?P<op>[-+*/^%]=|[=<>!]=|&&|\|\||[-+*/^%=<>!(){}\[\],;:#?~&|.])""",
    re.VERBOSE | re.DOTALL,
)


def tokens(text):
    """(kind, text, line) of every token; unknown characters or an unterminated string or
    comment raise ValueError."""
    out, pos, line = [], 0, 1
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            raise ValueError(f"line {line}: {text[pos : pos + 20]!r} is not allowed here")
        if m.lastgroup not in ("space", "comment"):
            out.append((m.lastgroup, m.group(), line))
        line += m.group().count("\n")
        pos = m.end()
    return out


def _assigned(toks, i):
    """Is the word at ``toks[i]`` the target of an assignment (``x =``, ``x[] =``, ``x +=``)?"""
    j = i + 1
    if j < len(toks) and toks[j][1] in ("[", "("):  # x[] = {...}, x(1) = ... (a list entry)
        closing = {"[": "]", "(": ")"}[toks[j][1]]
        while j < len(toks) and toks[j][1] != closing:
            j += 1
        j += 1
    return j < len(toks) and toks[j][1] in ("=", "+=", "-=", "*=", "/=")


def check_geo(text):
    """Refuse a ``.geo`` script that uses anything beyond plain geometry.

    Raises:
        ValueError: naming the line and the word, and what is allowed.
    """
    toks = tokens(text)
    variables = set()
    for i, (kind, word, line) in enumerate(toks):
        if kind != "word" or word in WORDS or word in variables:
            continue
        family = word.split(".")[0]
        if "." in word and family in OPTION_FAMILIES:
            continue
        if _VARIABLE.fullmatch(word) and _assigned(toks, i):
            variables.add(word)
            continue
        raise ValueError(
            f"line {line}: {word!r} is not allowed in a .geo file read by beamfx; allowed: "
            f"the geometry words {sorted(WORDS)}, options {', '.join(OPTION_FAMILIES)}.*, "
            "and variables (names starting with a lower-case letter) assigned before use; no "
            "loops, macros, includes, system calls or file writes"
        )


__all__ = ["OPTION_FAMILIES", "WORDS", "check_geo", "tokens"]
