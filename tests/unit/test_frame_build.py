"""The groupings that keep a frame's model build O(members): cells by beam, surface elements by
beam, beam names indexed once. Each must give what the comparison per beam gave."""

import numpy as np
import pytest


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_beam_cells_are_the_cells_of_each_beam_in_order(seed):
    """``beam_cells`` lists, for every beam with cells, exactly ``flatnonzero(cell_beam == i)``
    (ascending, as a boolean mask selects them); beams without cells are left out."""
    from beamfx.analyses.discretisation import beam_cells

    rng = np.random.default_rng(seed)
    n_beams = 40
    cell_beam = rng.integers(0, n_beams, 500)  # some beams get no cell
    cell_beam[cell_beam == 7] = 8
    got = beam_cells(cell_beam, n_beams)
    expected = [
        (i, np.flatnonzero(cell_beam == i)) for i in range(n_beams) if np.any(cell_beam == i)
    ]
    assert [i for i, _ in got] == [i for i, _ in expected]
    assert 7 not in dict(got)
    for (_, a), (_, b) in zip(got, expected):
        assert np.array_equal(a, b)


def test_surface_elements_by_beam():
    """``_beam_elements`` of the swept surface: each beam's elements in ascending order."""
    from beamfx.io.surface_cells import _beam_elements

    beam = np.array([3, 0, 3, 1, 0, 3], dtype=np.int64)
    got = _beam_elements(beam)
    assert sorted(got) == [0, 1, 3]
    for b in (0, 1, 3):
        assert np.array_equal(got[b], np.flatnonzero(beam == b))
    assert _beam_elements(np.zeros(0, np.int64)) == {}


def test_resolve_point_with_an_index_matches_without():
    """A point resolved with :func:`beam_index` given is the one resolved without it; a name
    of no beam fails the same way; a repeated name resolves to its first beam."""
    from beamfx.geometry.curves import Line
    from beamfx.physics.sections import rectangle
    from beamfx.spec import Beam, Model, resolve_point
    from beamfx.spec.model import beam_index

    sec = rectangle(2e11, 8e10, 7800, 0.1, 0.1)
    beams = [
        Beam(f"b{i}", Line((float(i), 0.0, 0.0), (float(i), 1.0, 0.0)), sec, 2) for i in range(5)
    ]
    beams.append(Beam("b2", Line((9.0, 0.0, 0.0), (9.0, 2.0, 0.0)), sec, 2))
    model = Model(beams=tuple(beams))
    index = beam_index(model)
    for at in ("b0:start", "b3:end", "b4:0.25", "b2:0.5"):
        b0, s0, x0 = resolve_point(model, at)
        b1, s1, x1 = resolve_point(model, at, index)
        assert (b0, s0) == (b1, s1) and np.array_equal(x0, x1)
    assert resolve_point(model, "b2:end", index)[0] == 2
    with pytest.raises(ValueError, match="names no beam") as a:
        resolve_point(model, "nope:start")
    with pytest.raises(ValueError, match="names no beam") as b:
        resolve_point(model, "nope:start", index)
    assert str(a.value) == str(b.value)
