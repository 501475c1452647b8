"""Form compilation with the JIT settings every beamfx form needs."""

import os
import time

from . import signature

JIT_PARAMS = {
    # another process (xdist worker, MPI rank, CI job) may compile the same form: wait for it
    # instead of the 10 s default (DOLFINx notes, section 9)
    "timeout": 600,
}


def _compile_flags(env=os.environ):
    """C compiler flags from ``BEAMFX_JIT_CFLAGS`` (e.g. "-O0 -g0" for the test suite, where
    compiling is most of a cold run and the kernels run briefly), with a cache folder of their
    own, so that kernels built with other flags are never mixed with the optimised ones
    (DOLFINx names a module by its form, not by the flags)."""
    flags = env.get("BEAMFX_JIT_CFLAGS", "").split()
    if not flags:
        return {}
    cache = os.path.join(env.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "fenics")
    tag = "_".join("".join(c for c in f if c.isalnum()) for f in flags)
    return {"cffi_extra_compile_args": flags, "cache_dir": f"{cache}-{tag}"}


JIT_PARAMS.update(_compile_flags())

#: seconds spent in dolfinx.fem.form, summed over the process (cold JIT and cached loads)
compile_seconds = [0.0]
#: number of forms compiled or loaded, to check that nothing is compiled twice
compile_count = [0]


def remember_loaded_modules():
    """Keep the JIT modules a process has loaded, by name, for the rest of the process.

    FFCx looks a cached form up on disk every time it is asked for it (a fresh
    ``importlib.machinery.FileFinder`` lists the whole cache folder: about 2.5 ms per form with
    5000 files in ``~/.cache/fenics``, half of a small run's time), although the module is
    loaded already. The module name is the hash of the form and its parameters, and a loaded
    extension module cannot change, so the second lookup is answered from memory. The first
    lookup of a module compiled and marked ready (``<name>.c.cached``) loads its extension file
    by name (:func:`_load_ready`) without listing the folder (6 ms a module with 11 000 files,
    the listing growing with every model a user has run); anything else (not compiled, being
    compiled by another process, another file name) goes through FFCx's lookup. The names
    themselves are hashed by :mod:`.signature` (UFL's bytes, fewer steps). Idempotent.
    """
    from ffcx.codegeneration import jit

    if getattr(jit.get_cached_module, "beamfx_memo", False):
        return
    _lazy_parameter_log()
    _expression_signature_once()
    signature.install()
    _lazy_form_constants()
    lookup, loaded = jit.get_cached_module, {}

    def get_cached_module(module_name, object_names, cache_dir, timeout):
        key = (module_name, str(cache_dir), tuple(object_names))
        if key not in loaded:
            found = _load_ready(module_name, object_names, cache_dir)
            if found is None:
                found = lookup(module_name, object_names, cache_dir, timeout)
            if found[0] is None:  # not compiled yet: this caller compiles it
                return found
            loaded[key] = found
        return loaded[key]

    get_cached_module.beamfx_memo = True
    get_cached_module.loaded = loaded
    jit.get_cached_module = get_cached_module


def _load_ready(module_name, object_names, cache_dir):
    """(compiled objects, module) of the JIT module ``module_name`` if FFCx marked it ready in
    ``cache_dir`` and its extension file has the interpreter's own suffix (what FFCx's
    ``FileFinder`` finds first), loaded as FFCx loads it; else None."""
    import importlib.machinery
    import importlib.util
    from pathlib import Path

    folder = Path(cache_dir)
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    path = folder / f"{module_name}{suffix}"
    if not (folder / f"{module_name}.c.cached").exists() or not path.exists():
        return None
    loader = importlib.machinery.ExtensionFileLoader(module_name, str(path))
    spec = importlib.util.spec_from_file_location(module_name, str(path), loader=loader)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return [getattr(module.lib, name) for name in object_names], module


def _expression_signature_once():
    """FFCx computes the signature of an expression twice per ``fem.Expression`` (for the
    module's name, then for the expression's, with the same UFL traversals: its own "FIXME
    ... cache the computation"), about 0.5 ms each time for a section expression. Its
    ``compute_signature`` is given a version that keeps the UFL part of the expression
    just asked for until the next call (the second of the pair, with the same objects) and
    hashes it with the tag as FFCx does, so the names are FFCx's own (checked in the tests);
    nothing is kept past the pair."""
    from ffcx import naming

    if getattr(naming.compute_signature, "beamfx_memo", False):
        return
    original, last = naming.compute_signature, [None]

    def compute_signature(ufl_objects, tag):
        import ufl

        if len(ufl_objects) != 1 or not isinstance(ufl_objects[0], tuple):
            return original(ufl_objects, tag)
        expr, points = ufl_objects[0]
        if not isinstance(expr, ufl.core.expr.Expr):
            return original(ufl_objects, tag)
        if last[0] is not None and last[0][0] is expr and last[0][1] is points:
            part, last[0] = last[0][2], None  # the second call of the pair: let it go
        else:
            part = _expression_part(expr, points)
            last[0] = (expr, points, part)
        return _combined(part, "expression", tag)

    compute_signature.beamfx_memo, compute_signature.original = True, original
    naming.compute_signature = compute_signature


def _expression_part(expr, points):
    """The part of FFCx 0.5's ``naming.compute_signature`` that an (expression, points) pair
    adds: the UFL signature of ``expr`` with its coefficients, constants, arguments and
    domains renumbered, then ``repr(points)`` (the same steps, in the same order)."""
    import ufl
    from ufl.algorithms.analysis import extract_constants, extract_type, unique_tuple

    coeffs = ufl.algorithms.extract_coefficients(expr)
    consts = extract_constants(expr)
    args = ufl.algorithms.analysis.extract_arguments(expr)
    rn = {c: i for i, c in enumerate(coeffs)}
    rn.update((c, i) for i, c in enumerate(consts))
    rn.update((c, i) for i, c in enumerate(args))
    domains = []  # append(*x) as FFCx: one domain each
    for c in coeffs:
        domains.append(*c.ufl_domains())
    for a in args:
        domains.append(*a.ufl_function_space().ufl_domains())
    for g in extract_type(expr, ufl.classes.GeometricQuantity):
        domains.append(*g.ufl_domains())
    domains += [c.ufl_domain() for c in consts]
    rn.update((d, i) for i, d in enumerate(unique_tuple(domains)))
    return ufl.algorithms.signature.compute_expression_signature(expr, rn) + repr(points)


def _combined(object_signature, kind, tag):
    """FFCx 0.5's hash of an object signature, its version and code generation, kind and tag."""
    import hashlib

    import ffcx.codegeneration

    parts = [
        object_signature,
        str(ffcx.__version__),
        ffcx.codegeneration.get_signature(),
        kind,
        tag,
    ]
    return hashlib.sha1(";".join(parts).encode("utf-8")).hexdigest()


def _lazy_form_constants():
    """UFL 2022.2's ``Form.__init__`` lists the form's constants at once, a traversal of every
    integrand, and every sum, difference, scaling and derivative of forms makes a new Form:
    eleven traversals of the energy while the condensed roll-up builds its residual and
    tangent (about a millisecond, a tenth of the model's build), of which only the two
    compiled forms read theirs. Form is given an ``__init__`` that leaves the list to its
    first read (``constants``, ``constant_numbering`` and the signature's renumbering): the
    same list, the same signatures. Idempotent."""
    import ufl.form as uf
    from ufl.algorithms.analysis import extract_constants
    from ufl.log import error

    Form = uf.Form
    if getattr(Form.constants, "beamfx_lazy", False):
        return
    renumbering, original = Form._compute_renumbering, Form.__init__

    def __init__(self, integrals):  # UFL's, but for the constants
        if not all(isinstance(itg, uf.Integral) for itg in integrals):
            error("Expecting list of integrals.")
        self._integrals = uf._sorted_integrals(integrals)
        self._integration_domains = self._domain_numbering = self._subdomain_data = None
        self._arguments = self._coefficients = self._coefficient_numbering = None
        self._constants = self._constant_numbering = None  # at first read
        self._hash = self._signature = None
        self._cache = {}

    def _listed(self):
        if self._constants is None:
            self._constants = extract_constants(self)
            self._constant_numbering = {c: i for i, c in enumerate(self._constants)}

    def constants(self):
        _listed(self)
        return self._constants

    def constant_numbering(self):
        """Return a contiguous numbering of constants in a mapping ``{constant:number}``."""
        _listed(self)
        return self._constant_numbering

    def _compute_renumbering(self):
        _listed(self)
        return renumbering(self)

    constants.beamfx_lazy, __init__.original = True, original
    Form.__init__, Form.constants, Form.constant_numbering = __init__, constants, constant_numbering
    Form._compute_renumbering = _compute_renumbering


class _Formatted:
    """``pprint.pformat(obj)`` made only when a log record shows it (``str``)."""

    __slots__ = ("obj",)

    def __init__(self, obj):
        self.obj = dict(obj)

    def __str__(self):
        import pprint

        return pprint.pformat(self.obj)


def _lazy_parameter_log():
    """FFCx formats its merged parameters with ``pprint`` for an INFO log line at every
    ``get_parameters``, shown or not (twice per form or expression: about 0.15 ms each, a
    tenth of a small run's whole time); its ``pprint`` is given a ``pformat`` that formats
    only when the line is shown. The log, when enabled, reads the same."""
    import types

    from ffcx import parameters

    if isinstance(getattr(parameters, "pprint", None), types.ModuleType):
        parameters.pprint = types.SimpleNamespace(pformat=_Formatted)


def compile_form(form):
    """``dolfinx.fem.form`` with the project's JIT parameters; records time and count."""
    import dolfinx.fem

    remember_loaded_modules()
    t = time.perf_counter()
    compiled = dolfinx.fem.form(form, jit_params=JIT_PARAMS)
    compile_seconds[0] += time.perf_counter() - t
    compile_count[0] += 1
    return compiled
