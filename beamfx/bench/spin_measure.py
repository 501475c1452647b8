"""The spin-up manoeuvre's measure (VM258), numpy only: the hub angle ψ(t), the least value and
the time mean of a sampled history read between the samples, and the four scored quantities.

beamfx's bench (:mod:`.transient`) and the peer scripts (``peers/common.py``, in their own
venv without beamfx's dependencies: they load this file by its path) score with this one
module, so beamfx and the peers are measured alike.
"""

import numpy as np

_trapezoid = getattr(np, "trapezoid", None) or np.trapz  # numpy 2 renamed it


def hub_angle(t):
    """ψ(t) of vm258_spin_up.json: (6/15)(t²/2 + (15/2π)²(cos(2πt/15) − 1)), then 6t − 45."""
    t = np.asarray(t, float)
    ramp = (6 / 15) * (t**2 / 2 + (15 / (2 * np.pi)) ** 2 * (np.cos(2 * np.pi * t / 15) - 1))
    return np.where(t < 15, ramp, 6 * t - 45)


def least(t, y):
    """The least value of the smooth function sampled as ``y`` at times ``t``: the quartic
    through the five samples around the least sample, minimised between its neighbours, so
    that the sampling adds an error O(dt⁵) instead of the O(dt²) of the least sample."""
    i = int(np.argmin(y))
    lo = min(max(i - 2, 0), max(len(y) - 5, 0))
    ts, ys = t[lo : lo + 5], y[lo : lo + 5]
    if len(ts) < 5 or i in (0, len(y) - 1):  # at an end: the sample is the extreme
        return float(y[i])
    scale = ts[-1] - ts[0]
    poly = np.polynomial.Polynomial.fit((ts - t[i]) / scale, ys, 4, domain=[-1, 1], window=[-1, 1])
    a, b = (t[i - 1] - t[i]) / scale, (t[i + 1] - t[i]) / scale
    roots = poly.deriv().roots()
    candidates = [r.real for r in roots if abs(r.imag) < 1e-12 and a <= r.real <= b]
    return float(min([y[i], *(poly(r) for r in candidates)]))


def time_mean(t, y, start, end):
    """Mean of the sampled ``y`` over [``start``, ``end``] (samples at both ends): Simpson's
    rule on a uniform even grid, else the trapezoidal rule."""
    m = (t >= start - 1e-9) & (t <= end + 1e-9)
    ts, ys = t[m], y[m]
    span = ts[-1] - ts[0]
    if np.ptp(np.diff(ts)) < 1e-6 * (ts[1] - ts[0]) and len(ts) % 2 == 1:
        h = span / (len(ts) - 1)
        area = h / 3 * (ys[0] + ys[-1] + 4 * ys[1:-1:2].sum() + 2 * ys[2:-1:2].sum())
    else:
        area = _trapezoid(ys, ts)
    return float(area / span)


def spin_up_values(t, x, y, theta, length):
    """The scored quantities from the tip history: times ``t``, positions (``x``, ``y``), the
    planar angle ``theta`` (needs no unwrapping) and the beam's ``length``: least axial and
    transverse tip displacement in the rotating frame and least rotation relative to the hub
    (each between the samples: :func:`least`), mean stretch over 15–18 s (:func:`time_mean`)."""
    t, x, y, theta = (np.asarray(a, float) for a in (t, x, y, theta))
    psi = hub_angle(t)
    c, s = np.cos(psi), np.sin(psi)
    axial = c * x + s * y - length
    return {
        "axial_min": least(t, axial),
        "transverse_min": least(t, -s * x + c * y),
        "relative_rotation_min": least(t, theta - psi),
        "stretch_mean_15_18": time_mean(t, axial, 15.0, 18.0),
    }
