"""Plain-float mathematics the rest of the core is built on.

- :mod:`.ddouble` — double-double (two-float) arithmetic for phases that must not lose ε·|t|;
- :mod:`.carlson` — Carlson's symmetric integrals R_F, R_D, R_J, R_C;
- :mod:`.elliptic_periods` — per-parameter constants of the elliptic kernels (K in double-double),
  K(m), and the reduction of arguments by the periods;
- :mod:`.jacobi` — the Jacobian elliptic functions sn, cn, dn and the amplitude am, every m ≥ 0;
- :mod:`.elliptic_integrals` — F(φ|m), Π(φ, n|m) and Fukushima's pn(u, n|m), every m ≥ 0;
- :mod:`.pn_fourier` — the periodic part of pn(u, n ≤ 0 | m < 1) as a sine series in the nome;
- :mod:`.elliptic` — the elliptic layer's one import point: the public names of the four above;
- :mod:`.rotations` — quaternions (scalar first), rotation matrices and the 3-1-3 Euler sequence.

Nothing here knows about bodies, torques or time: it is the bottom layer of ``spinorbit.core``.
"""
