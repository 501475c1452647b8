"""The Pai beam, upright and base-excited (Howcroft et al. 2016): sweeps and backbone of mode 2.

A thin titanium strip (50.8 × 0.45 mm, L = 0.479 m) stands clamped upright under its own weight;
the clamp moves sideways, in the flap plane, by y(t) = A sin φ(t), φ = 2π∫f dt, with f swept
slowly 7 → 11 Hz and back. The second bending mode (≈ 10 Hz) resonates; its large-amplitude
frequency falls (softening: the inertia of the tip's axial motion outweighs the curvature
stiffening for this mode), so the resonance leans to lower frequencies and the up and down
sweeps jump at different frequencies. The backbone, the frequency of free oscillation as a
function of its amplitude, comes from a free decay started with a mode-2 velocity field.

Model: planar (xy), the beam along +y, gravity along −y, the clamp moving along x; the flap
bending stiffness acts in the plane (section z = global z, EI_z = EI_flap). "0.005 %
stiffness-proportional damping" is read as the Kelvin–Voigt relaxation time a1 = 5e-5 s
(:class:`~beamfx.analyses.transient.TransientSettings` ``damping_stiffness``), which is a
damping ratio ζ_k = a1 ω_k / 2 ≈ 0.16 % in mode 2.
"""

import time
from dataclasses import dataclass
from itertools import pairwise
from typing import NamedTuple

import numpy as np

from ..geometry import Line
from ..physics.kinematics import Kinematics
from ..physics.sections import Section
from ..spec import Beam, Model, Support
from ._builders import CLAMP
from .registry import Case, reference, register

PAI = reference("howcroft_2016.json", "pai_beam")


def _property(prefix):
    """A property of the reference file by the start of its key (the keys carry notes)."""
    return next(v for k, v in PAI["properties"].items() if k.split(" ")[0] == prefix)


L = _property("L")
GRAVITY = 9.81
DAMPING = 5e-5  # a1 (s): "0.005 %" stiffness-proportional damping
AMPLITUDE = 1e-3  # ±1 mm clamp motion


def pai_section():
    """The strip's section, with the in-plane (flap) bending as EI_z.

    EA and GA are not in the reference: E and G follow from EI_flap = E w h³/12 and
    GJ = G w h³/3 (thin strip), with shear factor 5/6. Section y is the thickness direction,
    so rho_I = (polar, chord, flap).
    """
    h, w = _property("height"), _property("width")  # thickness along section y, width along z
    EI_flap, EI_chord, GJ = _property("EI_flap"), _property("EI_chord"), _property("GJ")
    rho_A, rho_J = _property("mass_per_length"), _property("torsional_inertia_per_length")
    A = w * h
    E, G = EI_flap / (w * h**3 / 12), GJ / (w * h**3 / 3)
    return Section(
        EA=E * A,
        GA_y=5 / 6 * G * A,
        GA_z=5 / 6 * G * A,
        GJ=GJ,
        EI_y=EI_chord,
        EI_z=EI_flap,
        rho_A=rho_A,
        rho_I=(rho_J, rho_A * w**2 / 12, rho_A * h**2 / 12),
    )


def pai_model(elements=5, degree=3, amplitude=0.0, history=None, gravity=True):
    """The upright planar cantilever named "b"; the clamp moves along x by amplitude·history(t)."""
    beam = Beam("b", Line((0.0, 0.0, 0.0), (0.0, L, 0.0)), pai_section(), elements, degree)
    clamp = Support("b:start", CLAMP, displacement=(amplitude, 0.0, 0.0), history=history)
    g = (0.0, -GRAVITY, 0.0) if gravity else (0.0, 0.0, 0.0)
    return Model((beam,), (clamp,), gravity=g, kinematics=Kinematics(plane="xy"))


@dataclass(frozen=True)
class Sweep:
    """Clamp motion A·e(t)·sin φ(t): a smooth amplitude ramp e over ``ramp`` seconds at
    ``f_start``, then f linear from ``f_start`` to ``f_end`` over ``duration`` seconds."""

    f_start: float
    f_end: float
    duration: float
    amplitude: float = AMPLITUDE
    ramp: float = 1.0

    @property
    def t_end(self):
        """Time at the end of the sweep (s): the ramp plus the sweep."""
        return self.ramp + self.duration

    @property
    def rate(self):
        """Sweep rate df/dt (Hz/s)."""
        return (self.f_end - self.f_start) / self.duration

    def frequency(self, t):
        """Instantaneous forcing frequency f(t) (Hz): ``f_start`` during the ramp, then linear."""
        s = np.clip(np.asarray(t, float) - self.ramp, 0.0, self.duration)
        return self.f_start + self.rate * s

    def phase(self, t):
        """φ(t) = 2π ∫₀ᵗ f dt."""
        t = np.asarray(t, float)
        s = np.clip(t - self.ramp, 0.0, self.duration)
        after = np.maximum(t - self.t_end, 0.0)
        cycles = self.f_start * np.minimum(t, self.ramp) + self.f_start * s + 0.5 * self.rate * s**2
        return 2 * np.pi * (cycles + self.f_end * after)

    def history(self, t):
        """The clamp displacement over its amplitude (the support's ``history``)."""
        t = np.asarray(t, float)
        e = np.where(
            t < self.ramp, 0.5 * (1 - np.cos(np.pi * np.minimum(t, self.ramp) / self.ramp)), 1.0
        )
        return e * np.sin(self.phase(t))


class Trace(NamedTuple):
    """The tip response of a transient run, with its cost."""

    t: np.ndarray
    tip: np.ndarray  # tip displacement along x relative to the clamp (m)
    steps: int
    newton_iterations: int
    seconds: float  # wall time of the time loop (without building the model)
    unknowns: int
    coordinate: np.ndarray | None = None  # a modal coordinate, where recorded


def settle(model, steps=1):
    """Static equilibrium under gravity (the pre-stressed state all runs start from).

    The relative tolerance is loosened: the weight (0.48 N) is small against the axial
    stiffness (EA = 2.9e6 N), so the residual's round-off floor (~1e-9 N) lies above
    solve_static's default absolute tolerance (1e-10 of the load norm)."""
    from ..analyses.static import solve_static

    solve_static(model, steps=steps, options={"snes_rtol": 1e-7, "snes_stol": 1e-8})
    return model.w.x.array.copy()


def _march(model, settings, saved=None, coordinate=None):
    """Run :func:`solve_transient` and record the tip displacement relative to the clamp,
    and ``coordinate(unknowns)`` (a number computed from the unknowns' array) if given."""
    from ..analyses.dofs import point_displacement, point_displacement_dofs
    from ..analyses.transient import solve_transient

    tip_dofs = point_displacement_dofs(model, "b:end")
    base_dofs = point_displacement_dofs(model, "b:start")
    t, tip, q = [], [], []

    def record(at):
        t.append(at)
        tip.append((point_displacement(model, tip_dofs) - point_displacement(model, base_dofs))[0])
        if coordinate is not None:
            q.append(coordinate(model.w.x.array))

    if saved is not None:  # a start from a given state: solve_transient reports no step 0
        header, arrays = saved
        model.w.x.array[:] = arrays["q_n"]
        record(header["t"])
    t0 = time.perf_counter()
    result = solve_transient(model, settings, on_step=lambda r: record(r.time), saved=saved)
    seconds = time.perf_counter() - t0
    return Trace(
        np.array(t),
        np.array(tip),
        len(result.steps),
        result.newton_iterations,
        seconds,
        model.unknowns(),
        np.array(q) if coordinate is not None else None,
    )


def transient_settings(t_end, dt, damping=DAMPING, rho_inf=0.9):
    """Transient settings of the sweeps and decays (stiffness-proportional ``damping``)."""
    from ..analyses.transient import TransientSettings

    return TransientSettings(
        t_end=t_end, dt=dt, rho_inf=rho_inf, damping_stiffness=damping, checkpoint_every=0
    )


def run_sweep(sweep, dt=0.0025, elements=5, degree=3, damping=DAMPING):
    """The tip response to a clamp sweep, from the gravity-loaded rest state."""
    from ..analyses.model import BeamModel

    spec = pai_model(elements, degree, sweep.amplitude, sweep.history)
    model = BeamModel(spec, extra_points=["b:end"])
    settle(model)
    return _march(model, transient_settings(sweep.t_end, dt, damping))


class Envelope(NamedTuple):
    """Response amplitude (m) against forcing frequency (Hz), one point per forcing cycle."""

    frequency: np.ndarray  # forcing frequency at the middle of each forcing cycle (Hz)
    amplitude: np.ndarray  # half the peak-to-peak tip displacement in that cycle (m)


def envelope(trace, sweep):
    """Amplitude per forcing cycle (after the ramp) against the instantaneous frequency."""
    cycles = np.floor(sweep.phase(trace.t) / (2 * np.pi)).astype(int)
    first = int(np.ceil(sweep.phase(sweep.ramp) / (2 * np.pi)))
    f, a = [], []
    for k in range(first, cycles.max()):
        sel = cycles == k
        if np.count_nonzero(sel) < 4:
            continue
        a.append(0.5 * (trace.tip[sel].max() - trace.tip[sel].min()))
        f.append(sweep.frequency(trace.t[sel].mean()))
    return Envelope(np.array(f), np.array(a))


def peak(env):
    """(frequency, amplitude) of the largest cycle amplitude."""
    i = int(np.argmax(env.amplitude))
    return float(env.frequency[i]), float(env.amplitude[i])


# --- linear modes and the backbone from free decay -------------------------------------------


class Modes(NamedTuple):
    """Linear modes about the gravity-loaded state and the modal coordinate of mode 2."""

    hz: np.ndarray
    second: np.ndarray  # mode-2 vector (unknowns' layout), scaled to unit tip displacement
    static: np.ndarray  # the gravity-loaded state
    coordinate: object  # q2(w) = φ2ᵀM(w − w_static) / φ2ᵀMφ2: mode 2's share of a state (m)


def linear_modes(model, n_modes=4):
    """Frequencies about the gravity-loaded state, the second bending mode, and its modal
    coordinate (the M-orthogonal projection, blind to the other linear modes).

    The planar model's lowest modes are bending modes (axial and shear ones are kHz)."""
    import dolfinx.fem.petsc as fp

    from ..analyses.dofs import point_displacement, point_displacement_dofs
    from ..analyses.modal import mass_ufl, solve_modes
    from ..solvers.forms import compile_form

    static = settle(model)
    result = solve_modes(model, n_modes=n_modes)
    phi = result.modes[1]
    tip = point_displacement(model, point_displacement_dofs(model, "b:end"), phi.x.array)[0]
    phi.x.array[:] /= tip
    M = fp.assemble_matrix(compile_form(mass_ufl(model)), bcs=model.bcs, diagonal=0.0)
    M.assemble()
    Mphi = M.createVecLeft()
    M.mult(phi.vector, Mphi)
    owned = len(Mphi.array_r)
    m_phi = Mphi.array_r.copy()
    comm = model.comm
    norm = comm.allreduce(float(np.dot(m_phi, phi.x.array[:owned])))
    M.destroy()
    Mphi.destroy()

    def coordinate(w):
        return comm.allreduce(float(np.dot(m_phi, w[:owned] - static[:owned]))) / norm

    return Modes(result.hz, phi.x.array.copy(), static, coordinate)


def run_free_decay(tip_velocity, t_end, dt=0.0025, elements=5, degree=3, damping=DAMPING):
    """Free vibration from the gravity-loaded state with the mode-2 velocity field scaled to
    ``tip_velocity`` at the tip (the initial amplitude is about tip_velocity/ω2). Starting
    at the equilibrium with a purely transverse velocity puts the motion on the nonlinear
    mode to second order (the axial motion of the mode is quadratic in the amplitude, its
    rate vanishes there). The trace records the tip displacement and the modal coordinate
    q2 (in metres of tip displacement), which the free mode-1 motion that the start leaves
    does not disturb. Returns (trace, modes)."""
    from ..analyses.model import BeamModel

    model = BeamModel(pai_model(elements, degree), extra_points=["b:end"])
    modes = linear_modes(model)
    zero = np.zeros_like(modes.static)
    arrays = {
        "q_n": modes.static,
        "v_n": tip_velocity * modes.second,
        "a_n": zero,
        "qdd_n": zero.copy(),
    }
    header = {  # a checkpoint's (header, arrays): solve_transient goes on from this state
        "t": 0.0,
        "step": 0,
        "controller": {"size": dt},
        "balance": {
            "values": dict.fromkeys(("work_loads", "work_supports", "dissipated_damping"), 0.0),
            "initial": None,
            "power": None,
        },
    }
    saved = (header, arrays)
    settings = transient_settings(t_end, dt, damping)
    return _march(model, settings, saved, modes.coordinate), modes


class Backbone(NamedTuple):
    """Amplitude (m) against frequency (Hz) of a free decay: the backbone curve."""

    amplitude: np.ndarray  # half the peak-to-peak tip displacement over one period (m)
    frequency: np.ndarray  # 1 / period between successive upward zero crossings (Hz)


def upward_crossings(t, x):
    """Times where x crosses zero upwards (linear interpolation between samples)."""
    i = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


def high_pass(t, x, cutoff):
    """Signal x without its content below ``cutoff`` Hz (4th-order Butterworth, run forwards and
    backwards: no phase shift); t uniformly spaced."""
    from scipy.signal import butter, sosfiltfilt

    sos = butter(4, cutoff, "highpass", fs=1.0 / (t[1] - t[0]), output="sos")
    return sosfiltfilt(sos, x)


def backbone(trace, cutoff=4.0):
    """Instantaneous frequency against amplitude, period by period, of a free decay.

    Periods from the upward zero crossings of the modal coordinate (of the tip displacement
    if the trace has none). Amplitudes are of the tip displacement, as in :func:`envelope`,
    so that the backbone and the sweeps' envelopes share their axes; the free mode-1 motion
    (1.4 Hz) that the start leaves is filtered out of it above ``cutoff`` Hz, and the periods
    within 2/cutoff of the end (the filter's edge transient) are left out. The start needs no
    such care: a decay from the equilibrium starts at zero like a sine, which the filter's
    odd extension continues exactly. (At large
    amplitude the tip's sideways excursion grows more slowly than q2: the tip also drops.)"""
    x = trace.coordinate if trace.coordinate is not None else trace.tip
    tc = upward_crossings(trace.t, x)
    tip = trace.tip
    if cutoff:
        tip = high_pass(trace.t, trace.tip, cutoff)
        tc = tc[tc <= trace.t[-1] - 2.0 / cutoff]
    a = []
    for t0, t1 in pairwise(tc):
        sel = (trace.t >= t0) & (trace.t <= t1)
        a.append(0.5 * (tip[sel].max() - tip[sel].min()))
    return Backbone(np.array(a), 1.0 / np.diff(tc))


def backbone_slope(bb, upto):
    """The fit f = f0 + c·a² over amplitudes below ``upto`` (Hz, Hz/m²): the first
    nonlinear term of a symmetric oscillator; c < 0 is softening."""
    sel = bb.amplitude <= upto
    c, f0 = np.polyfit(bb.amplitude[sel] ** 2, bb.frequency[sel], 1)
    return float(f0), float(c)


# --- the registered case: the linear limit and the softening sign, from free decays ---------

SMALL, LARGE = 0.05, 3.0  # tip velocities (m/s): amplitudes about 0.8 mm and 4.5 cm


def decay_measure(elements, degree, dt, t_end=0.5):
    """Mode-2 frequencies of a small and a large free decay over the linear modal f2.

    ``f2_ratio`` → 1 as dt → 0 (the generalized-α period error is about (ω dt)²/12);
    ``softening`` is 1 if the large-amplitude frequency is lower, else 0."""
    small, modes = run_free_decay(SMALL, t_end, dt, elements, degree)
    large, _ = run_free_decay(LARGE, t_end, dt, elements, degree)
    bs, bl = backbone(small, cutoff=0), backbone(large, cutoff=0)  # frequencies only
    f_small, f_large = float(np.mean(bs.frequency)), float(np.mean(bl.frequency))
    f2 = float(modes.hz[1])
    return {
        "f2_ratio": f_small / f2,
        "softening": float(f_large < f_small),
        "f2_modal": f2,
        "f_small": f_small,
        "a_small": float(np.mean(bs.amplitude)),
        "f_large": f_large,
        "a_large": float(np.mean(bl.amplitude)),
        "steps": small.steps + large.steps,
        "newton_iterations": small.newton_iterations + large.newton_iterations,
        "unknowns": small.unknowns,
    }


@dataclass(frozen=True)
class DecayCase(Case):
    """Settings are (elements, degree, dt); each runs two free decays (cold, then warm)."""

    def run_setting(self, elements, degree, dt):
        """One row of the table: the decay's values, unknowns and cold and warm wall times."""
        from ..solvers.forms import compile_seconds

        c0, t0 = compile_seconds[0], time.perf_counter()
        values = decay_measure(elements, degree, dt)
        cold, jit = time.perf_counter() - t0, compile_seconds[0] - c0
        t1 = time.perf_counter()
        decay_measure(elements, degree, dt)
        warm = time.perf_counter() - t1
        return {
            "elements": elements,
            "degree": degree,
            "dt": dt,
            "unknowns": values.pop("unknowns"),
            "newton_iterations": values.pop("newton_iterations"),
            "load_steps": values.pop("steps"),
            "wall_s_cold": cold,
            "wall_s_warm": warm,
            "jit_s": jit,
            "values": values,
        }


register(
    DecayCase(
        id="pai_beam_mode2_decay",
        paper="Howcroft et al. (2016), the Pai beam upright and base-excited",
        title="Upright Pai beam under gravity: mode-2 free decay, linear limit and softening",
        build=None,
        measure=None,
        reference={"f2_ratio": 1.0, "softening": 1.0},
        tolerance=1e-3,
        scale=1.0,
        settings=((5, 3, 0.005), (5, 3, 0.0025), (5, 3, 0.00125)),
        own_model="its own solver path (free decays from the gravity-loaded state started "
        "with a mode-2 velocity field, read from the solver's history), not a scene; the "
        "model is the planar (xy) one, built so",
        note=(
            "Planar model, gravity along the upright beam, a1 = 5e-5 s stiffness-proportional "
            "damping. Free decays from the gravity-loaded state with a mode-2 velocity field; "
            "the frequency is read from upward zero crossings of the mode-2 coordinate. "
            "f2_ratio: small-amplitude (≈0.8 mm tip) frequency over the linear modal f2 of the "
            "pre-stressed state (the integrator's period error ≈ (ω dt)²/12 sets it); "
            "softening: 1 if the ≈4.5 cm decay oscillates slower. The sweeps and the full "
            "backbone are in demos/pai_beam.py and docs/pai_beam.md."
        ),
    )
)


# --- output: the amplitude–frequency plot and its CSV ---------------------------------------


def write_csv(path, sweeps, bb):
    """One row per forcing cycle of each sweep ((Sweep, Envelope) pairs) and per period of
    the backbone: curve (up, down, backbone), sweep rate, frequency, amplitude."""
    import csv

    with open(path, "w", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["curve", "sweep_rate_hz_per_s", "frequency_hz", "amplitude_m"])
        for sw, env in sweeps:
            kind = "up" if sw.rate > 0 else "down"
            for f, a in zip(env.frequency, env.amplitude):
                out.writerow([kind, f"{sw.rate:.6g}", f"{f:.6f}", f"{a:.6e}"])
        for f, a in zip(bb.frequency, bb.amplitude):
            out.writerow(["backbone", "", f"{f:.6f}", f"{a:.6e}"])


def plot(path, sweeps, bb, f2):
    """Envelopes of the sweeps (up solid, down dashed, one colour per rate), the backbone
    (dots) and the linear f2 (dotted line), as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    rates = sorted({abs(sw.rate) for sw, _ in sweeps}, reverse=True)
    for sw, env in sweeps:
        up = sw.rate > 0
        ax.plot(
            env.frequency,
            1e3 * env.amplitude,
            "-" if up else "--",
            color=colours[rates.index(abs(sw.rate)) % len(colours)],
            lw=1,
            label=f"{'up' if up else 'down'}, {abs(sw.rate):.3g} Hz/s",
        )
    ax.plot(bb.frequency, 1e3 * bb.amplitude, "k.", ms=4, label="backbone (free decay)")
    ax.axvline(f2, color="grey", lw=0.8, ls=":", label=f"linear f2 = {f2:.3f} Hz")
    ax.set_xlabel("forcing frequency; backbone: free frequency (Hz)")
    ax.set_ylabel("tip displacement amplitude relative to the clamp (mm)")
    ax.set_title("Upright Pai beam under gravity, clamp ±1 mm: mode-2 resonance")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
