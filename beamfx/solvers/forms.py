"""Form compilation with the JIT settings every beamfx form needs."""

import time

JIT_PARAMS = {
    # another process (xdist worker, MPI rank, CI job) may compile the same form: wait for it
    # instead of the 10 s default (DOLFINx notes, section 9)
    "timeout": 600,
}

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
    extension module cannot change, so the second lookup is answered from memory. Idempotent.
    """
    from ffcx.codegeneration import jit

    if getattr(jit.get_cached_module, "beamfx_memo", False):
        return
    _lazy_parameter_log()
    lookup, loaded = jit.get_cached_module, {}

    def get_cached_module(module_name, object_names, cache_dir, timeout):
        key = (module_name, str(cache_dir), tuple(object_names))
        if key not in loaded:
            found = lookup(module_name, object_names, cache_dir, timeout)
            if found[0] is None:  # not compiled yet: this caller compiles it
                return found
            loaded[key] = found
        return loaded[key]

    get_cached_module.beamfx_memo = True
    get_cached_module.loaded = loaded
    jit.get_cached_module = get_cached_module


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
