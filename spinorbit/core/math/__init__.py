"""Plain-float mathematics the rest of the core is built on.

- :mod:`.ddouble` — double-double (two-float) arithmetic for phases that must not lose ε·|t|;
- :mod:`.elliptic` — Jacobian elliptic functions and elliptic integrals, every parameter m ≥ 0;
- :mod:`.rotations` — quaternions (scalar first), rotation matrices and the 3-1-3 Euler sequence.

Nothing here knows about bodies, torques or time: it is the bottom layer of ``spinorbit.core``.
"""
