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


def compile_form(form):
    """``dolfinx.fem.form`` with the project's JIT parameters; records time and count."""
    import dolfinx.fem

    t = time.perf_counter()
    compiled = dolfinx.fem.form(form, jit_params=JIT_PARAMS)
    compile_seconds[0] += time.perf_counter() - t
    compile_count[0] += 1
    return compiled
