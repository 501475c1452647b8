"""The expression hash data that names compiled forms (:mod:`beamfx.solvers.signature`) is
UFL's own, byte for byte: on the forms of every kind of model a run builds (planar and
spatial condensed, full, planar full, mixed; residual, tangent, mass, follower coupling), in
the order a run signs them and in other orders (the digests one form leaves for the next are
reused only where they hold), and it keeps no model alive."""

import gc
import weakref

import pytest
import ufl
from mpi4py import MPI
from ufl.algorithms import signature as ufl_signature

from beamfx.analyses.modal import mass_ufl
from beamfx.analyses.planar_condensed import build_model
from beamfx.bench import all_cases
from beamfx.solvers import signature
from beamfx.solvers.forms import remember_loaded_modules

# (case, elements, degree, condensed): planar condensed, spatial condensed with a follower
# force, full spatial (quaternion), full planar, mixed
MODELS = [
    ("rollup_0.5", 2, 1, True),
    ("sm23_end_moments", 2, 3, True),
    ("bend45_follower", 1, 4, True),
    ("bend45_vertical", 2, 2, False),
    ("rollup_0.5", 2, 2, False),
    ("sm28_free_free_timoshenko", 1, 2, False),
    ("sm28_free_free_eigen", 2, 3, False),
]


def _spec(case_id, elements, degree):
    """The model of the case's scene, as the scene builder chose it (planar where it is)."""
    from beamfx.bench.scenes import SceneCase, setting_scene

    case = all_cases()[case_id]
    if isinstance(case, SceneCase):
        return case.scenes(elements, degree)[0].model
    return setting_scene(case, (elements, degree)).model


def _forms(model):
    """The forms of ``model`` a run compiles, in a run's order."""
    from beamfx.analyses.model import BeamModel

    forms = [model.F, model.J]
    if isinstance(model, BeamModel):  # a full model: its mass form (modal)
        forms.append(mass_ufl(model, "full"))
    if getattr(model, "_followers", None):  # the follower forces' coupling forms
        forms += [ufl.derivative(x * model.dx, model.w) for x in model.x_dot]
    return forms


def _ufl_own(form):
    """The signature of ``form`` by UFL's own hash data and traversals (a fresh Form: none
    cached)."""
    import importlib

    fresh = ufl.Form(form.integrals())
    modules = [importlib.import_module(name) for name in signature._TRAVERSING]
    ufl_signature.compute_expression_hashdata = signature.compute_expression_hashdata.original
    for module in modules:
        module.traverse_unique_terminals = signature.unique_terminals.original
    try:
        return fresh.signature()
    finally:
        ufl_signature.compute_expression_hashdata = signature.compute_expression_hashdata
        for module in modules:
            module.traverse_unique_terminals = signature.unique_terminals


@pytest.mark.parametrize("case_id, elements, degree, condensed", MODELS)
@pytest.mark.parametrize("order", ["run", "reversed"])
def test_form_signatures_are_ufl_own(case_id, elements, degree, condensed, order):
    remember_loaded_modules()
    assert ufl_signature.compute_expression_hashdata is signature.compute_expression_hashdata
    model = build_model(_spec(case_id, elements, degree), MPI.COMM_WORLD, (), condensed)
    forms = _forms(model)
    if order == "reversed":
        forms = forms[::-1]
    for form in forms:
        expected = _ufl_own(form)
        assert ufl.Form(form.integrals()).signature() == expected


def test_expression_signatures_are_ufl_own():
    """An expression's signature (FFCx names the section expressions by it) after a form of
    the same model was signed: UFL's own."""
    from ufl.algorithms.signature import compute_expression_signature

    remember_loaded_modules()
    model = build_model(_spec("bend45_vertical", 1, 4), MPI.COMM_WORLD, (), True)
    ufl.Form(model.F.integrals()).signature()  # leaves its digests for the next call
    expr = ufl.as_vector([*model.section_parts()[2], model.load_factor])
    renumbering = {c: i for i, c in enumerate(ufl.algorithms.extract_coefficients(expr))}
    renumbering[model.load_factor] = 0
    renumbering[model.mesh.mesh.ufl_domain()] = 0
    got = compute_expression_signature(expr, renumbering)
    ufl_signature.compute_expression_hashdata = signature.compute_expression_hashdata.original
    try:
        assert got == compute_expression_signature(expr, renumbering)
    finally:
        ufl_signature.compute_expression_hashdata = signature.compute_expression_hashdata


def test_digests_are_reused_only_where_the_terminals_agree():
    """The tangent of a residual reuses the residual's digests; a form whose terminals are
    numbered otherwise (the residual's test function as the second argument) reuses none,
    and still gets UFL's signature."""
    remember_loaded_modules()
    model = build_model(_spec("sm23_end_moments", 2, 3), MPI.COMM_WORLD, (), True)
    ufl.Form(model.F.integrals()).signature()
    carried = signature._carried[0]
    assert carried is not None and carried[1]
    assert signature._reusable(_terminal_data(model.J)) is carried[1]
    ufl.Form(model.F.integrals()).signature()
    v = ufl.TestFunction(model.W)
    swapped = ufl.replace(model.F, {v: ufl.TrialFunction(model.W)})  # argument number 1
    assert signature._reusable(_terminal_data(swapped)) == {}
    assert ufl.Form(swapped.integrals()).signature() == _ufl_own(swapped)


def _terminal_data(form):
    integrands = [i.integrand() for i in form.integrals()]
    return ufl_signature.compute_terminal_hashdata(integrands, form._compute_renumbering())


def test_the_digests_and_terminals_kept_keep_no_model_alive():
    """Digests left for the next form, and the terminal lists of the nodes traversed, go
    with the model."""
    remember_loaded_modules()
    model = build_model(_spec("rollup_0.5", 2, 1), MPI.COMM_WORLD, (), True)
    ufl.Form(model.J.integrals()).signature()
    assert signature._carried[0] is not None
    integrand = model.J.integrals()[0].integrand()
    assert id(integrand) in signature._terminals
    key, gone = id(integrand), weakref.ref(model.w)
    del model, integrand
    gc.collect()
    assert gone() is None
    assert key not in signature._terminals


def test_terminals_are_listed_once_in_ufl_order():
    """A node's terminals, asked for again, come from the list of the first traversal: the
    same objects in the same order as UFL's own traversal."""
    from ufl.algorithms import analysis

    remember_loaded_modules()
    model = build_model(_spec("bend45_vertical", 1, 4), MPI.COMM_WORLD, (), True)
    integrand = model.F.integrals()[0].integrand()
    own = list(signature.unique_terminals.original(integrand))
    first = list(analysis.traverse_unique_terminals(integrand))
    again = list(ufl_signature.traverse_unique_terminals(integrand))
    assert signature._terminals[id(integrand)][1] is not None
    assert [id(t) for t in first] == [id(t) for t in again] == [id(t) for t in own]


def _random_forms(seed, trials):
    """Forms of random expressions that share subexpressions (the same objects) across forms
    and trials, with test and trial functions, coefficients of two spaces, a constant and
    free indices: residuals, their derivatives and functionals, in a shuffled order."""
    import random

    rng = random.Random(seed)
    cell = ufl.triangle
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", cell, 1))
    V = ufl.FunctionSpace(domain, ufl.FiniteElement("Lagrange", cell, 1))
    W = ufl.FunctionSpace(domain, ufl.VectorElement("Lagrange", cell, 2))
    scalars = [ufl.Coefficient(V) for _ in range(4)] + [ufl.Constant(domain)]
    vectors = [ufl.Coefficient(W) for _ in range(2)]
    pool = []

    def scalar(depth=0):
        r = rng.random()
        if depth > 3 or r < 0.3:
            return rng.choice(scalars + [ufl.as_ufl(rng.choice((1.0, 2.0)))])
        if pool and r < 0.45:
            return rng.choice(pool)
        a, b = scalar(depth + 1), scalar(depth + 1)
        g = ufl.grad(rng.choice(vectors))
        e = rng.choice(
            (
                lambda: a * b,
                lambda: a + b,
                lambda: ufl.sin(a),
                lambda: ufl.dot(g[0, :], ufl.as_vector([a, b])),
                lambda: ufl.inner(g, ufl.grad(rng.choice(vectors))) * a,
                lambda: ufl.conditional(ufl.lt(a, b), a, b),
            )
        )()
        pool.append(e)
        return e

    for _ in range(trials):
        v, u, c = ufl.TestFunction(V), ufl.TrialFunction(V), rng.choice(scalars[:4])
        F = scalar() * v * ufl.dx + scalar() * ufl.inner(ufl.grad(v), ufl.grad(c)) * ufl.ds
        forms = [F, ufl.derivative(F, rng.choice(scalars[:4]), u), (scalar() + c) * ufl.dx]
        rng.shuffle(forms)
        yield from forms


def test_random_forms_sharing_nodes_are_signed_as_ufl_does():
    """UFL's signature on forms whose nodes recur across forms with other numberings of their
    coefficients, arguments and indices (the digests carried from form to form are reused
    only where they hold: without the terminals' check, dozens of these differ)."""
    remember_loaded_modules()
    for form in _random_forms(1, 60):
        assert ufl.Form(form.integrals()).signature() == _ufl_own(form)


def test_digests_of_freed_nodes_are_not_taken_by_new_nodes_at_their_ids():
    """Forms over the same terminals, each freed before the next is built (whose nodes then
    take the freed ids while the digests carried from form to form are reused): UFL's
    signature every time."""
    import random

    remember_loaded_modules()
    rng = random.Random(3)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.triangle, 1))
    V = ufl.FunctionSpace(domain, ufl.FiniteElement("Lagrange", ufl.triangle, 1))
    f, g, v = ufl.Coefficient(V), ufl.Coefficient(V), ufl.TestFunction(V)
    ops = (lambda a, b: a * b, lambda a, b: a + b, lambda a, b: ufl.sin(a) - b)

    def tree(depth):
        if depth == 0:
            return rng.choice((f, g))
        return rng.choice(ops)(tree(depth - 1), tree(rng.randrange(depth)))

    for _ in range(200):
        form = (tree(4) + f * g) * v * ufl.dx
        assert ufl.Form(form.integrals()).signature() == _ufl_own(form)
        del form
