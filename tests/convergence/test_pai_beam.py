"""The upright base-excited Pai beam: sweep bookkeeping, the linear limit of mode 2 and the
softening of its backbone (beamfx.bench.pai_beam)."""

import numpy as np
import pytest

from beamfx.bench import pai_beam as pb


def test_section_matches_the_reference_properties():
    """EI_z is the flap stiffness (in the plane of motion); the polar inertia given in the
    reference equals rho_A (w² + h²)/12 of the 50.8 × 0.45 mm strip."""
    s = pb.pai_section()
    assert s.EI_z == pb._property("EI_flap") and s.EI_y == pb._property("EI_chord")
    assert np.isclose(s.rho_I[1] + s.rho_I[2], s.rho_I[0], rtol=1e-3)
    assert s.EA > 1e7 * s.EI_z  # a thin strip: stretching is ~1e8 times stiffer than flapping


def test_sweep_phase_is_the_integral_of_the_frequency():
    sw = pb.Sweep(7.0, 11.0, 10.0, ramp=0.5)
    t = np.linspace(0.0, 12.0, 240001)
    dphi = np.gradient(sw.phase(t), t)
    assert np.allclose(dphi[1:-1], 2 * np.pi * sw.frequency(t[1:-1]), rtol=1e-6)
    assert sw.frequency(sw.t_end) == 11.0 and sw.history(0.0) == 0.0
    assert np.max(np.abs(np.diff(sw.history(t)))) < 2 * np.pi * 11 * 5e-5 * 1.01  # continuous


def test_envelope_and_backbone_of_synthetic_signals():
    """A steady sine of amplitude 2 under the sweep gives envelope 2 at every cycle; a chirped
    decaying oscillation gives its instantaneous frequency and amplitude."""
    sw = pb.Sweep(7.0, 11.0, 4.0, ramp=0.5)
    t = np.arange(0.0, sw.t_end, 1e-4)
    trace = pb.Trace(t, 2.0 * np.sin(sw.phase(t) + 0.3), 0, 0, 0.0, 0)
    env = pb.envelope(trace, sw)
    assert np.allclose(env.amplitude, 2.0, rtol=1e-5)
    assert np.all(np.diff(env.frequency) > 0) and 7.0 < env.frequency[0] < 7.2

    # instantaneous frequency 10 − 0.2 t Hz, amplitude exp(−0.1 t)
    x = np.exp(-0.1 * t) * np.sin(2 * np.pi * (10.0 * t - 0.1 * t**2))
    bb = pb.backbone(pb.Trace(t, x, 0, 0, 0.0, 0), cutoff=0)
    assert np.all(np.diff(bb.frequency) < 0) and np.all(np.diff(bb.amplitude) < 0)
    assert 10.0 - 0.2 * t[-1] < bb.frequency.min() and bb.frequency.max() < 10.0
    assert np.exp(-0.1 * t[-1]) < bb.amplitude.min() and bb.amplitude.max() < 1.0
    filtered = pb.backbone(pb.Trace(t, x + 0.5 * np.sin(2 * np.pi * 1.4 * t), 0, 0, 0.0, 0, x))
    assert np.allclose(
        filtered.amplitude,
        np.interp(filtered.frequency, bb.frequency[::-1], bb.amplitude[::-1]),
        rtol=1e-2,
    )


@pytest.fixture(scope="module")
def decays():
    """Free decays of mode 2 at three amplitudes (tip about 0.8 mm, 2.2 cm, 4.4 cm)."""
    return {v: pb.run_free_decay(v, 0.4, dt=0.0025) for v in (0.05, 1.5, 3.0)}


def test_small_amplitude_decay_oscillates_at_the_modal_frequency(decays):
    """Linear limit: the free decay's frequency is the pre-stressed modal f2 (≈ 10.42 Hz with
    gravity, 10.63 without), up to the generalized-α period error ≈ (ω dt)²/12 (ρ∞ = 0.9)."""
    trace, modes = decays[0.05]
    f2 = modes.hz[1]
    assert 10.3 < f2 < 10.5
    bb = pb.backbone(trace, cutoff=0)  # the amplitude only roughly: no filter needed
    assert np.all(bb.amplitude < 1e-3)
    error = np.mean(bb.frequency) / f2 - 1
    period_error = (2 * np.pi * f2 * 0.0025) ** 2 / 12  # 2.2e-3
    assert -1.3 * period_error < error < -0.7 * period_error, (error, period_error)


def test_backbone_softens(decays):
    """Mode 2 of the cantilever softens: frequency falls with amplitude, and f = f0 + c a²
    with c < 0 fits the three decays with f0 near the linear frequency."""
    bbs = [pb.backbone(decays[v][0], cutoff=0) for v in (0.05, 1.5, 3.0)]
    a = np.concatenate([b.amplitude for b in bbs])
    f = np.concatenate([b.frequency for b in bbs])
    means = [np.mean(b.frequency) for b in bbs]
    assert means[0] > means[1] > means[2]
    assert means[0] - means[2] > 0.4  # about 0.5 Hz at 4.4 cm
    f0, c = pb.backbone_slope(pb.Backbone(a, f), upto=0.05)
    assert c < 0
    assert abs(f0 - means[0]) < 0.02


@pytest.mark.slow
def test_short_sweep_through_resonance_peaks_below_the_linear_frequency():
    """A 12 s up-sweep 9.5 → 10.7 Hz at ±1 mm (about 50 s): the response peaks near mode 2,
    at a frequency that the sweep lag and the softening both shift, well above the small
    forced amplitude at its start."""
    sw = pb.Sweep(9.5, 10.7, 12.0)
    trace = pb.run_sweep(sw)
    env = pb.envelope(trace, sw)
    f_peak, a_peak = pb.peak(env)
    assert 9.9 < f_peak < 10.7
    assert a_peak > 3 * env.amplitude[0]
