r"""Beam physics as short pure functions returning UFL.

Notation (Simo 1985; Simo & Vu-Quoc 1986), used in every function of this package:

=============  ==============================================================================
symbol         meaning
=============  ==============================================================================
``s``          arc length of the reference centre line
``X, t0``      reference centre line and its unit tangent :math:`t_0 = dX/ds`
``Λ0``         reference section frame, columns :math:`(t_0, e_2, e_3)` (section x, y, z axes)
``u``          displacement of the centre line (global axes)
``q``          incremental rotation quaternion :math:`q = (q_0, \mathbf v)`, :math:`Λ = R(q) Λ0`
``R``          rotation matrix of ``q`` (any norm: :math:`R(q) = R(q/|q|)`)
``Γ``          material translational strain :math:`Γ = Λ0^T (R^T (t_0 + u') - t_0)`
``K``          material curvature change :math:`K = Λ0^T\,\mathrm{axial}(R^T R')`
``C_N, C_M``   section stiffness diag(EA, GA_y, GA_z) and diag(GJ, EI_y, EI_z)
``N, M``       section force :math:`C_N Γ` and moment :math:`C_M K` in section axes
``θ``          small rotation vector (linear kinematics only)
=============  ==============================================================================

A prime is the derivative along ``s``. Vectors are in global axes unless the docstring says
"section axes". The rotation is total Lagrangian and singularity free: the quaternion field
passes any angle (2π, 4π, ...) without special treatment, and ``R`` and ``K`` do not depend on
the norm of ``q``; a penalty on :math:`(|q|^2 - 1)^2` only removes that null direction.

Each function imports ``ufl`` itself: the scene layer uses :class:`~.kinematics.Kinematics`
and the sections, and ``beamfx check`` should not pay for UFL (with pkg_resources) to read a
file.
"""
