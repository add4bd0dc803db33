"""Andoyer variables (L, G, H; l, g, h) from an attitude and a body angular momentum, and back.

Conventions (``docs/conventions.md``, checked numerically in ``tests/test_andoyer.py``):

- G = |M| (angular momentum), H = its inertial z component, L = its body z (C-axis) component.
- Attitude (inertial → body) R = R3(l) R1(J) R3(g) R1(I) R3(h), cos I = H/G, cos J = L/G.
- Body angular momentum M = (√(G² − L²) sin l, √(G² − L²) cos l, L).
- Inertial angular momentum Rᵀ M = G (sin I sin h, −sin I cos h, cos I).

The two Andoyer singularities are inherited, not hidden: at I = 0 (M along the inertial z axis) only
g + h is defined, at J = 0 (M along the body C axis) only l + g. The functions here still return
finite, consistent numbers there (the split is made by a fixed rule documented on each function), so
that attitude → Andoyer → attitude is a round trip to rounding everywhere. Choosing an inertial
frame far from I = 0 is the caller's job (``spinorbit.state`` does it automatically).
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.math.rotations import attitude_to_euler313, rot3


@jit
def node_frame(cos_i, sin_i, h):
    """Passive rotation R1(I) R3(h): inertial frame → frame whose z axis is the angular momentum."""
    r = np.empty((3, 3))
    ch, sh = math.cos(h), math.sin(h)
    r[0, 0] = ch
    r[0, 1] = sh
    r[0, 2] = 0.0
    r[1, 0] = -cos_i * sh
    r[1, 1] = cos_i * ch
    r[1, 2] = sin_i
    r[2, 0] = sin_i * sh
    r[2, 1] = -sin_i * ch
    r[2, 2] = cos_i
    return r


@jit
def andoyer_from_attitude(attitude, momentum_body):
    """Andoyer variables of a rotation state.

    Parameters
    ----------
    attitude : (3, 3) ndarray
        Attitude matrix R (inertial → body, principal axes A ≤ B ≤ C on body x, y, z).
    momentum_body : (3,) ndarray
        Angular momentum in the body frame, M = I ω (any consistent unit).

    Returns
    -------
    L, G, H, l, g, h : float
        Momenta in the unit of M; angles in radians, each in (−π, π].

    Notes
    -----
    h = atan2(M_I,x, −M_I,y) from the inertial momentum M_I = Rᵀ M; l = atan2(M_x, M_y) from the body
    momentum; g is then the 3-1-3 first angle of R · (R1(I) R3(h))ᵀ = R3(l) R1(J) R3(g), whose middle
    angle J and last angle l agree with the momentum-based ones. At I = 0 the rule gives h = 0
    (atan2(0, −0) conventions aside) and g carries g + h; at J = 0 the 3-1-3 gimbal-lock rule gives
    l = 0 and g carries l + g.
    """
    mx, my, mz = momentum_body[0], momentum_body[1], momentum_body[2]
    big_g = math.sqrt(mx * mx + my * my + mz * mz)
    m_inertial = attitude.T @ momentum_body
    big_h = m_inertial[2]
    sin_i = math.hypot(m_inertial[0], m_inertial[1]) / big_g
    cos_i = big_h / big_g
    h = math.atan2(m_inertial[0], -m_inertial[1])
    frame = node_frame(cos_i, sin_i, h)
    # R = R3(l) R1(J) R3(g) · frame, so R · frameᵀ is a 3-1-3 product with angles (g, J, l).
    g, _, l = attitude_to_euler313(attitude @ frame.T)
    return mz, big_g, big_h, l, g, h


@jit
def attitude_from_andoyer(big_l, big_g, big_h, l, g, h):
    """Attitude matrix R = R3(l) R1(J) R3(g) R1(I) R3(h) and body angular momentum of Andoyer variables.

    Returns
    -------
    attitude : (3, 3) ndarray
        Inertial → body.
    momentum_body : (3,) ndarray
        (√(G² − L²) sin l, √(G² − L²) cos l, L), in the unit of G.

    Notes
    -----
    sin J and sin I come from √((G − L)(G + L)) and √((G − H)(G + H)), which keep full relative
    accuracy near J = 0 and I = 0, where G² − L² would cancel.
    """
    transverse = math.sqrt(max((big_g - big_l) * (big_g + big_l), 0.0))
    sin_j, cos_j = transverse / big_g, big_l / big_g
    sin_i = math.sqrt(max((big_g - big_h) * (big_g + big_h), 0.0)) / big_g
    cos_i = big_h / big_g
    frame = node_frame(cos_i, sin_i, h)
    r1j = np.empty((3, 3))
    r1j[0, 0], r1j[0, 1], r1j[0, 2] = 1.0, 0.0, 0.0
    r1j[1, 0], r1j[1, 1], r1j[1, 2] = 0.0, cos_j, sin_j
    r1j[2, 0], r1j[2, 1], r1j[2, 2] = 0.0, -sin_j, cos_j
    attitude = rot3(l) @ r1j @ rot3(g) @ frame
    momentum = np.empty(3)
    momentum[0] = transverse * math.sin(l)
    momentum[1] = transverse * math.cos(l)
    momentum[2] = big_l
    return attitude, momentum


@jit
def kinetic_energy_andoyer(big_l, big_g, l, a, b, c):
    """Kinetic energy ½[(G² − L²)(a sin² l + b cos² l) + c L²] (paper eq. 10), a, b, c = 1/A, 1/B, 1/C."""
    sl, cl = math.sin(l), math.cos(l)
    return 0.5 * ((big_g - big_l) * (big_g + big_l) * (a * sl * sl + b * cl * cl) + c * big_l * big_l)

