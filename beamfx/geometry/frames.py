"""Reference section frames of a centre line, in NumPy.

A frame Λ0 is a 3 × 3 matrix whose columns are the unit tangent t and the section axes e2, e3
(global axes). The convention is that of the UFL frame of the beam model
(:func:`beamfx.physics.kinematics.section_frame`): e3 is an orientation vector made normal to
t, e2 = e3 × t, and both are then turned by a twist angle about t. The solid, the continuum
beam and the model checks use these functions, so every part of beamfx agrees on the frame.
"""

import numpy as np


def default_reference(tangents):
    """The default orientation vector per tangent (rows): global z, or global x where the
    centre line runs along z (|t_z| > 1 − 1e-8).

    Args:
        tangents: (n, 3) unit tangents, global axes.

    Returns:
        (n, 3) orientation vectors, global axes (not yet normal to the tangents).
    """
    along_z = np.abs(np.asarray(tangents)[:, 2]) > 1 - 1e-8
    return np.where(along_z[:, None], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])


def frame_from_tangent(t, orientation=None, twist_deg=0.0):
    """Section frame Λ0 (columns t, e2, e3) where the unit tangent is ``t``.

    e3 is ``orientation`` (or :func:`default_reference` if None) made normal to t, e2 = e3 × t,
    both turned by ``twist_deg`` degrees about t.

    Args:
        t: unit tangent (3,), global axes.
        orientation: orientation vector (3,), global axes, not parallel to t; None: default.
        twist_deg: turn of the section about t, degrees.

    Returns:
        (3, 3) orthonormal matrix.
    """
    t = np.asarray(t, float)
    ref = default_reference(t[None])[0] if orientation is None else orientation
    e3 = np.asarray(ref, float) - np.dot(ref, t) * t
    e3 /= np.linalg.norm(e3)
    e2 = np.cross(e3, t)
    c, sn = np.cos(np.deg2rad(twist_deg)), np.sin(np.deg2rad(twist_deg))
    e2, e3 = c * e2 + sn * e3, -sn * e2 + c * e3
    return np.column_stack([t, e2, e3])


def tangent_at(curve, s, rel_step=1e-6):
    """Unit tangent of ``curve`` at arc length ``s``, by a difference over ±``rel_step``·L
    (one-sided at the ends)."""
    L = curve.length
    h = rel_step * L
    a, b = max(s - h, 0.0), min(s + h, L)
    t = np.diff(curve.points([a, b]), axis=0)[0]
    return t / np.linalg.norm(t)


def section_axes_at(curve, s, orientation=None, twist_deg=0.0):
    """Section frame Λ0 (columns t, e2, e3) of a beam on ``curve`` at arc length ``s``, with
    its ``orientation`` vector and ``twist_deg`` (:func:`frame_from_tangent`; a number, or a
    function of the arc length)."""
    if callable(twist_deg):
        twist_deg = float(np.asarray(twist_deg(np.array([s], float)))[0])
    return frame_from_tangent(tangent_at(curve, s), orientation, twist_deg)
