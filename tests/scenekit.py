"""Scenes and models shared by tests of several folders (importable as ``scenekit``)."""

import numpy as np
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.geometry import Line
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.sections import Section, tube
from beamfx.spec import Beam, Model, PointLoad, Support

E, G, RHO = 210e9, 80.77e9, 7850.0

# A cantilever under a follower force and moment at its tip, a semitangential moment and a
# dead force at mid-length: the statically condensed model's loads of every kind (its tip
# turns by about 11 degrees)
CONDENSED_LOADS = """
[material]
E = 210e9
nu = 0.3
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [2, 0, 0] }
section = { type = "rectangle", h = 0.1, w = 0.05 }
elements = 4
degree = 3
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
force = [0, 2e4, 6e4]
moment = [0, 3e4, 0]
kind = "follower"
[[loads]]
at = "b:0.5"
moment = [2e4, 0, 1e4]
kind = "semitangential"
[[loads]]
at = "b:0.5"
force = [0, -3e4, 0]
[model]
kinematics = "finite"
plane = "none"
[analysis]
type = "static"
steps = 4
"""
CLAMP = ("ux", "uy", "uz", "rx", "ry", "rz")

# A clamped steel strip shaken at its root (analysis type replaced by the test)
SHAKEN = """
[material]
E = 210e9
nu = 0.3
rho = 7850
[[beams]]
name = "arm"
curve = { shape = "line", start = [0, 0, 0], end = [0, 0, 0.5] }
section = { type = "rectangle", h = 0.002, w = 0.03 }
elements = 4
[[supports]]
at = "arm:start"
fix = "all"
displacement = [0.02, 0, 0]
history = "(1 - cos(pi * t / 0.2)) / 2"
[analysis]
type = "ANALYSIS"
[[probes]]
name = "tip"
at = "arm:end"
"""

# The linear cantilever of the 3D solid, curve and section filled in by the test
SOLID_SCENE = """
[material]
E = 2.1e11
nu = 0.3

[[beams]]
name = "b"
curve = {curve}
section = {section}
elements = 2
degree = 3

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [0, 0, 1e4]

[analysis]
type = "linear_static"
"""

# The roll-up of a straight cantilever under an end moment (``turns`` full turns)
comm = MPI.COMM_WORLD
L, EI = 10.0, 215e3
SECTION = Section(EA=1770e3, GA_y=1770e3, GA_z=1770e3, GJ=8.16e3, EI_y=EI, EI_z=EI)
ELEMENTS, DEGREE = 8, 3
# tip error of this mesh in the two-turn roll-up is 1.4e-5 L (notes §11), at half a turn 5e-10 L;
# the stress resultants converge at O(h^4) and are off by 3e-6 here
TOL_POSITION, TOL_MOMENT = 1e-5, 1e-5


def rollup_model(turns, comm=comm):
    M = turns * 2 * np.pi * EI / L
    spec = Model(
        beams=(Beam("b", Line((0, 0, 0), (L, 0, 0)), SECTION, ELEMENTS, DEGREE),),
        supports=(Support("b:start", ("ux", "uy", "uz", "rx", "ry", "rz")),),
        point_loads=(PointLoad("b:end", moment=(0, -M, 0)),),
    )
    return BeamModel(spec, comm), M


def hat(t):
    """The load pulse of the flying spaghetti: 0 → 1 at 2.5 s → 0 at 5 s."""
    t = np.asarray(t, float)
    return np.clip(np.where(t < 2.5, t / 2.5, (5 - t) / 2.5), 0.0, None)


def flying_spaghetti(elements=8, degree=2):
    """Simo & Vu-Quoc (1986), planar: a free beam from (6, 0) to (0, 8) thrown by a force 8
    along x and a moment 80 about z at its lower end, both with the hat pulse."""
    section = Section(1e4, 1e4, 1e4, 500.0, 500.0, 500.0, 1.0, (20.0, 10.0, 10.0))
    beam = Beam("b", Line((6, 0, 0), (0, 8, 0)), section, elements, degree)
    load = PointLoad("b:start", (8.0, 0.0, 0.0), (0.0, 0.0, 80.0), "dead", hat)
    return Model((beam,), (), (load,), kinematics=Kinematics(plane="xy"))


def pulse(t):
    """A smooth pulse on [0, 0.05] s: zero value and slope at both ends."""
    t = np.asarray(t, float)
    return np.where(t < 0.05, 0.5 * (1 - np.cos(2 * np.pi * t / 0.05)), 0.0)


def cantilever(history=pulse, force=(0.0, 300.0, 400.0), elements=2, degree=2, kin=None):
    """Steel tube cantilever, 1 m, first bending period about 0.07 s; 3D, quaternions."""
    section = tube(E, G, RHO, 0.02)
    beam = Beam("b", Line((0, 0, 0), (1.0, 0, 0)), section, elements, degree)
    return Model(
        (beam,),
        (Support("b:start", CLAMP),),
        (PointLoad("b:end", force, (0.0, 0.0, 0.0), "dead", history),),
        kinematics=kin or Kinematics(),
    )


#: the hub's angle of the spin-up of tests/scenes/test_restart.py: the tip passes 2π at 0.96 s
SPIN_HISTORY = "where(t < 0.5, 4 * (t - (0.5 / pi) * sin(pi * t / 0.5)), 8 * t - 2)"


def spun_beam(history, t_end, dt=0.005, plane="none", checkpoint_every=None):
    """A transient scene: a 10 m beam clamped to a hub turning about z by ``history``, the
    tip probed (the spin-up of the restart, MPI-failure and VM258 tests)."""
    checkpoints = "" if checkpoint_every is None else f"checkpoint_every = {checkpoint_every}\n"
    return f"""
[[beams]]
name = "beam"
curve = {{ shape = "line", start = [0, 0, 0], end = [10, 0, 0] }}
section = {{ type = "general", EA = 2.8e7, GA_y = 1e7, GA_z = 1e7, GJ = 1.4e4, EI_y = 1.4e4, EI_z = 1.4e4, rho_A = 1.2, rho_I = [1.2e-3, 6e-4, 6e-4] }}
elements = 4
degree = 2
[model]
plane = "{plane}"
[[supports]]
at = "beam:start"
fix = "all"
rotation = [0, 0, 1]
history = "{history}"
[analysis]
type = "transient"
t_end = {t_end!r}
dt = {dt!r}
{checkpoints}[[probes]]
name = "tip"
at = "beam:end"
"""


def run_whole_and_restarted(folder, whole, short):
    """Run the scene text ``whole`` into ``folder/whole``; run ``short`` (the same scene
    stopped earlier, with checkpoints) into ``folder/parts`` and restart ``whole`` there.
    Returns the probes.csv of both (whole, parts) as structured arrays."""
    from beamfx.runner import run_scene

    quiet = {"log": lambda m: None}
    (folder / "a.toml").write_text(whole)
    (folder / "b.toml").write_text(short)
    run_scene(folder / "a.toml", folder / "whole", **quiet)
    run_scene(folder / "b.toml", folder / "parts", **quiet)
    run_scene(folder / "a.toml", folder / "parts", restart=True, **quiet)
    return tuple(
        np.genfromtxt(folder / name / "probes.csv", delimiter=",", names=True)
        for name in ("whole", "parts")
    )


# a clamped 1 m steel rod of 2 x P2 elements, modal with 30 modes: more than it has
MODAL_ROD = """
[material]
E = 210e9
rho = 7850

[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "circle", d = 0.02 }
elements = 2
degree = 2

[[supports]]
at = "b:start"
fix = "all"

[analysis]
type = "modal"
modes = 30
"""
