"""Forms are compiled once per model: load steps, time steps (also after a cut-back, which
changes dt), output at every step and a sweep over speeds reuse them.

Every form and expression reaches FFCx through ``dolfinx.jit.ffcx_jit`` (``fem.form``,
``fem.Expression``); a C compilation (cache miss) goes through FFCx's ``_compile_objects``.
Both are counted; neither may grow after the first step (or speed).
"""

from types import SimpleNamespace

import numpy as np
import pytest

from beamfx.analyses.model import BeamModel
from beamfx.bench._builders import CLAMP, cantilever, straight
from beamfx.io.probes import evaluate_points
from beamfx.physics import sections
from beamfx.physics.kinematics import Kinematics
from beamfx.spec import Beam, Model, Support


@pytest.fixture
def jit(monkeypatch):
    """Counts of forms and expressions handed to FFCx, and of C compilations."""
    import dolfinx.jit
    import ffcx.codegeneration.jit as ffcx_jit
    import ufl

    count = SimpleNamespace(forms=0, expressions=0, c_compiles=0)
    jit_call, compile_objects = dolfinx.jit.ffcx_jit, ffcx_jit._compile_objects

    def counting(comm, obj, *args, **kwargs):
        if isinstance(obj, ufl.Form):
            count.forms += 1
        elif isinstance(obj, tuple):
            count.expressions += 1
        return jit_call(comm, obj, *args, **kwargs)

    def compiling(*args, **kwargs):
        count.c_compiles += 1
        return compile_objects(*args, **kwargs)

    monkeypatch.setattr(dolfinx.jit, "ffcx_jit", counting)
    monkeypatch.setattr(ffcx_jit, "_compile_objects", compiling)
    count.now = lambda: (count.forms, count.expressions, count.c_compiles)
    return count


def fail_once(solve, at_call):
    """``solve`` that reports non-convergence at its ``at_call``-th call (forces a cut-back)."""
    calls = [0]

    def wrapped():
        calls[0] += 1
        report = solve()
        return report._replace(converged=calls[0] != at_call, reason="forced")

    return wrapped


def test_load_steps_and_cutbacks_compile_nothing(jit):
    from beamfx.analyses.static import solve_static
    from beamfx.solvers import NewtonSolver

    section = sections.Section(1e6, 1e6, 1e6, 1e3, 1e3, 2e3)
    spec = cantilever(straight(1.0), section, 4, 2, moment=(0, -np.pi * 1e3, 0))
    model = BeamModel(spec, extra_points=["b:end"])
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_count_")
    solver.solve = fail_once(solver.solve, 2)
    seen = []

    def on_step(step):
        evaluate_points(model, ["b:end"])  # output at every step, as beamfx run does
        seen.append(jit.now())

    result = solve_static(model, steps=4, solver=solver, on_step=on_step)
    assert any(s.cutbacks for s in result.steps)
    model.reset()
    solve_static(model, steps=3, solver=solver, on_step=on_step)  # a second run: same forms
    assert len(seen) >= 7 and len(set(seen)) == 1, seen
    solver.destroy()


def test_another_load_value_is_the_same_form():
    """Point-load vectors are constants of the forms: scenes that differ only in their load
    values share the residual's and tangent's signature (the JIT module's name), so a cold
    cache compiles them once; a moment added where there was none, or another kind of load,
    is another form."""
    section = sections.Section(1e6, 1e6, 1e6, 1e3, 1e3, 2e3)

    def signatures(force, moment, follower=False):
        spec = cantilever(straight(1.0), section, 4, 2, force, moment, follower)
        model = BeamModel(spec)
        return model.F.signature(), model.J.signature()

    first = signatures((0, 10.0, 20.0), (0, 0, 0))
    assert signatures((0, -30.0, 5.0), (0, 0, 0)) == first
    assert signatures((1.0, 0, 0), (0, 0, 0)) == first
    with_moment = signatures((0, -30.0, 5.0), (0, -50.0, 0))
    assert with_moment[0] != first[0] and with_moment[1] != first[1]
    assert signatures((0, 7.0, 5.0), (0, 3.0, 0)) == with_moment
    assert signatures((0, 7.0, 5.0), (0, 3.0, 0), follower=True) != with_moment


def test_time_steps_and_step_size_changes_compile_nothing(jit, monkeypatch):
    from beamfx.analyses import transient
    from beamfx.analyses.transient import TransientSettings, solve_transient
    from beamfx.bench.transient import spin_up_model

    class Failing(transient.NewtonSolver):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.solve = fail_once(self.solve, 3)

    monkeypatch.setattr(transient, "NewtonSolver", Failing)
    model = BeamModel(spin_up_model(4, 2), extra_points=["b:end"])
    seen, dts = [], []

    def on_step(r):
        evaluate_points(model, ["b:end"])
        seen.append(jit.now())
        dts.append(r.dt)

    settings = TransientSettings(t_end=0.4, dt=0.05, checkpoint_every=0)
    result = solve_transient(model, settings, on_step=on_step)
    assert any(s.cutbacks for s in result.steps) and len(set(dts[1:])) > 1  # dt changed
    assert len(set(seen)) == 1, seen


def test_speed_sweep_compiles_nothing_after_the_first_speed(jit):
    from beamfx.analyses.campbell import campbell
    from beamfx.analyses.rotating import RotatingFrame

    section = sections.rectangle(2.1e11, 2.1e11 / 2.6, 7850.0, 0.02, 0.05)
    spec = Model(
        beams=(Beam("b", straight(1.0), section, 3, 2),),
        supports=(Support("b:start", CLAMP),),
        kinematics=Kinematics(),
    )
    model = BeamModel(spec)
    frame = RotatingFrame(model, rotary="full")
    seen = []
    campbell(
        frame, [0.0, 20.0, 40.0, 60.0], n_modes=2, on_speed=lambda i, s: seen.append(jit.now())
    )
    frame.destroy()
    assert len(seen) == 4
    # the modes of the first speed are solved after on_speed: compare from the second speed on
    assert len(set(seen[1:])) == 1, seen


def test_a_loaded_jit_module_is_answered_from_memory():
    """A form compiled (or loaded) once is not looked up in the JIT cache folder again: the
    second request returns the very objects of the first (forms.remember_loaded_modules)."""
    import dolfinx
    import ufl
    from ffcx.codegeneration import jit
    from mpi4py import MPI

    from beamfx.solvers.forms import compile_form

    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_WORLD, 2)
    V = dolfinx.fem.FunctionSpace(mesh, ("Lagrange", 1))
    u = dolfinx.fem.Function(V)
    form = u * u * ufl.dx(metadata={"quadrature_degree": 2})
    first = compile_form(form)
    memo = jit.get_cached_module.loaded
    names = [k[0] for k in memo if k[0].startswith("libffcx_forms_")]
    assert names, "the form's module is remembered"
    second = compile_form(form)
    assert first.ufcx_form == second.ufcx_form


def test_ffcx_parameter_log_reads_the_same_when_shown(caplog, monkeypatch):
    """The FFCx parameter dump is formatted only when shown, and then as pprint formats it."""
    import logging
    import pprint

    import ffcx.parameters

    from beamfx.solvers.forms import remember_loaded_modules

    remember_loaded_modules()
    calls, pformat = [], pprint.pformat
    monkeypatch.setattr(pprint, "pformat", lambda *a, **k: calls.append(1) or pformat(*a, **k))
    ffcx.parameters.get_parameters()  # FFCx's default verbosity (WARNING): not shown
    assert not calls
    with caplog.at_level(logging.INFO, logger="ffcx"):
        params = ffcx.parameters.get_parameters({"verbosity": logging.INFO})
    assert pprint.pformat(params) in [r.getMessage() for r in caplog.records]
    ffcx.parameters.get_parameters()  # back to FFCx's default verbosity (WARNING)


def test_an_expression_signature_is_ffcx_own_and_computed_once(monkeypatch):
    """FFCx names an expression's module and the expression by two signatures of the same
    UFL: the patched ``compute_signature`` (forms.remember_loaded_modules) gives FFCx's own
    hashes and traverses the expression once for the pair."""
    import dolfinx
    import numpy as np
    import ufl
    from ffcx import naming
    from mpi4py import MPI
    from ufl.algorithms import signature

    from beamfx.solvers.forms import remember_loaded_modules

    remember_loaded_modules()
    ffcx_own = naming.compute_signature.original
    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_WORLD, 2)
    V = dolfinx.fem.FunctionSpace(mesh, ufl.VectorElement("Lagrange", mesh.ufl_cell(), 2, dim=2))
    u, c = dolfinx.fem.Function(V), dolfinx.fem.Constant(mesh, 2.0)
    J = ufl.Jacobian(mesh)[:, 0]
    expr = ufl.as_vector([c * u[0] * ufl.sqrt(ufl.dot(J, J)), ufl.cos(u[1])])
    points = np.array([[0.0], [0.5], [1.0]])
    for tag in ("libffcx_expressions_x", "prefix", "prefix"):
        assert naming.compute_signature([(expr, points)], tag) == ffcx_own([(expr, points)], tag)
    dolfinx.fem.Expression(expr, points)  # compiled (FFCx's code generation names it too)
    calls, traverse = [], signature.compute_expression_signature
    monkeypatch.setattr(
        signature, "compute_expression_signature", lambda *a: calls.append(1) or traverse(*a)
    )
    dolfinx.fem.Expression(expr, points)  # loaded: the pair of names of one look-up
    assert len(calls) == 1


def test_forms_list_their_constants_when_read_as_ufl_does():
    """A form made by sums, scalings and derivatives (each a new Form) lists its constants
    at the first read (forms.remember_loaded_modules): the same constants, numbering and
    signature as UFL's own Form.__init__, which lists them at once."""
    import dolfinx
    import ufl
    from mpi4py import MPI

    from beamfx.solvers.forms import remember_loaded_modules

    remember_loaded_modules()
    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_WORLD, 2)
    V = dolfinx.fem.FunctionSpace(mesh, ufl.FiniteElement("Lagrange", mesh.ufl_cell(), 1))
    u, v = dolfinx.fem.Function(V), ufl.TestFunction(V)
    a, b = dolfinx.fem.Constant(mesh, 2.0), dolfinx.fem.Constant(mesh, 3.0)
    Pi = a * u**2 * ufl.dx - b * u * ufl.ds
    F = ufl.derivative(Pi, u, v) - 0.5 * (b * v * ufl.dx)
    assert F._constants is None  # nothing listed yet
    eager = ufl.Form.__new__(ufl.Form)
    ufl.Form.__init__.original(eager, F.integrals())
    assert F.constants() == eager.constants() == [a, b]
    assert F.constant_numbering() == eager.constant_numbering()
    assert F.signature() == eager.signature()


def test_compile_flags_get_a_cache_of_their_own():
    """BEAMFX_JIT_CFLAGS (the test suite's "-O0 -g0") sets the C flags and a cache folder
    beside the default one, so kernels built with other flags never serve a user's run."""
    from beamfx.solvers.forms import _compile_flags

    assert _compile_flags({}) == {}
    assert _compile_flags({"BEAMFX_JIT_CFLAGS": "  "}) == {}
    got = _compile_flags({"BEAMFX_JIT_CFLAGS": "-O0 -g0", "XDG_CACHE_HOME": "/c"})
    assert got == {"cffi_extra_compile_args": ["-O0", "-g0"], "cache_dir": "/c/fenics-O0_g0"}


def test_a_ready_jit_module_is_loaded_by_name_as_ffcx_finds_it(tmp_path):
    """The first lookup of a compiled module loads its extension file by name
    (forms._load_ready, no listing of the cache folder): the module FFCx's own lookup finds,
    with the same objects; a module not compiled or not marked ready is left to FFCx."""
    import shutil

    import dolfinx
    import ufl
    from ffcx.codegeneration import jit
    from mpi4py import MPI

    from beamfx.solvers.forms import _load_ready, compile_form

    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_WORLD, 2)
    V = dolfinx.fem.FunctionSpace(mesh, ("Lagrange", 2))
    u = dolfinx.fem.Function(V)
    compile_form(u * u * u * ufl.dx(metadata={"quadrature_degree": 6}))
    memo = jit.get_cached_module.loaded
    (name, folder, objects) = next(k for k in memo if k[0].startswith("libffcx_forms_"))
    found = _load_ready(name, list(objects), folder)
    assert found is not None
    ffcx_objects, ffcx_module = memo[(name, folder, objects)]
    assert found[1].__file__ == ffcx_module.__file__
    assert [str(o) for o in found[0]] == [str(o) for o in ffcx_objects]
    assert _load_ready("libffcx_forms_not_there", list(objects), folder) is None
    # being compiled elsewhere: its C file and extension file there, not yet marked ready
    (tmp_path / f"{name}.c").write_text("")
    shutil.copy(ffcx_module.__file__, tmp_path)
    assert _load_ready(name, list(objects), tmp_path) is None
