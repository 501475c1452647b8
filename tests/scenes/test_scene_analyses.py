"""Modal and buckling analyses run from scene files (beamfx run): results.json and ParaView."""

import json

import numpy as np

from beamfx.runner import run_scene

CANTILEVER = """
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [2, 0, 0] }}
section = {{ type = "general", EA = 2e11, GA_y = 1e8, GA_z = 1e8, GJ = 1e4, EI_y = {EI}, EI_z = 4e4, rho_A = {rho_A}, rho_I = [1e-6, 1e-6, 1e-6] }}
elements = 8
degree = 3

[[supports]]
at = "b:start"
fix = "all"

[[probes]]
name = "tip"
at = "b:end"

[model]
shear = false

[output]
dir = "{out}"
"""


def _run(scene_file, text):
    return run_scene(scene_file(text), log=lambda *a: None)


def test_modal_scene_gives_the_euler_bernoulli_cantilever_frequencies(tmp_path, scene_file):
    EI, rho_A, L = 1e4, 2.0, 2.0
    text = CANTILEVER.format(EI=EI, rho_A=rho_A, out=tmp_path / "out")
    results = _run(
        scene_file, text + '[analysis]\ntype = "modal"\nmodes = 4\nrotary_inertia = "none"\n'
    )
    f = np.array(results["frequencies_hz"])
    beta = np.array([1.8751040687, 4.6940911330])
    exact = beta**2 / (2 * np.pi) * np.sqrt(EI / (rho_A * L**4))
    # the two lowest are the bending modes about y (EI_y < EI_z), then about z
    assert np.allclose(f[[0, 2]], exact, rtol=1e-5), (f, exact)
    assert np.isclose(f[1], exact[0] * 2, rtol=1e-5)  # EI_z = 4 EI_y: twice the frequency
    shapes = results["mode_shapes"]
    assert len(shapes) == 4 and abs(abs(shapes[0]["tip"][2]) - 1) < 1e-12  # tip moves most
    written = json.loads((tmp_path / "out" / "results.json").read_text())
    assert written["frequencies_hz"] == results["frequencies_hz"]
    assert (tmp_path / "out" / "deformed_0004.vtu").is_file()  # one ParaView step per mode


def test_buckling_scene_gives_the_euler_load(tmp_path, scene_file):
    EI, L = 1e4, 2.0
    text = CANTILEVER.format(EI=EI, rho_A=0.0, out=tmp_path / "out").replace("shear = false", "")
    text += (
        '[[loads]]\nat = "b:end"\nforce = [-1, 0, 0]\n\n[analysis]\ntype = "buckling"\nmodes = 2\n'
    )
    results = _run(scene_file, text)
    GA = 1e8
    euler = np.pi**2 * EI / (4 * L**2) * np.array([1, 4])  # EI_z = 4 EI_y
    engesser = euler / (1 + euler / GA)  # shear-flexible column (P/EA = 3e-8 is left out)
    assert np.allclose(results["load_factors"], engesser, rtol=1e-6), results["load_factors"]


def test_modal_scene_without_mass_is_an_error(tmp_path, scene_file):
    import pytest

    text = CANTILEVER.format(EI=1e4, rho_A=0.0, out=tmp_path / "out").replace(
        "rho_I = [1e-6, 1e-6, 1e-6]", "rho_I = [0, 0, 0]"
    )
    with pytest.raises(ValueError, match="needs mass"):
        _run(scene_file, text + '[analysis]\ntype = "modal"\n')
