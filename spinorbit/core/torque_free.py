"""The exact torque-free motion (paper eq. 12): S, Z, H, z, h constant, s = s0 + a S0 t.

Evaluates the solution at many times from one state. The motion constants, the elliptic constants
and the node frame R1(I) R3(h) are computed once; each time then costs one sn/cn/dn, one pn and one
sin/cos. Permanent rotations (no finite elements) are propagated as uniform rotations.
"""

import math

import numpy as np

from ._jit import jit
from .andoyer import node_frame
from .canonical import (
    MO_ARG_PER_S,
    MO_G_PER_S,
    MO_MODE,
    MO_PN_COEFF,
    MO_S_RATE,
    MODE_UNIFORM,
    body_from_argument,
    elements_from_state,
    elliptic_constants,
    flip_signs,
    inertia_constants,
    motion_from_momentum,
)
from .elliptic import pn_k


@jit
def uniform_rotation(attitude, momentum, big_a, big_b, big_c, t):
    """Attitude at time t of a permanent rotation (ω = I⁻¹M parallel to M, constant in both frames).

    R(t) = R_ω(t) R0 where R_ω(t) is the passive rotation by |ω| t about ω: the body turns about
    ω at the rate |ω| (Rodrigues' formula on the attitude matrix).
    """
    wx, wy, wz = momentum[0] / big_a, momentum[1] / big_b, momentum[2] / big_c
    rate = math.sqrt(wx * wx + wy * wy + wz * wz)
    if rate == 0.0:
        return attitude.copy()
    kx, ky, kz = wx / rate, wy / rate, wz / rate
    angle = rate * t
    ca, sa = math.cos(angle), math.sin(angle)
    k = np.array([kx, ky, kz])
    skew = np.array([[0.0, -kz, ky], [kz, 0.0, -kx], [-ky, kx, 0.0]])
    # passive rotation by +angle about k: cos·1 + (1 − cos) k kᵀ − sin [k]×
    rot_k = ca * np.eye(3) + (1.0 - ca) * np.outer(k, k) - sa * skew
    return rot_k @ attitude


@jit
def torque_free_attitudes(attitude, momentum, big_a, big_b, big_c, times):
    """Exact torque-free attitudes at many times (paper eq. 12), as (N, 3, 3) attitude matrices.

    The motion constants, the elliptic constants and the node frame R1(I) R3(h) are computed once;
    each time then costs one sn/cn/dn, one pn and one sin/cos.
    """
    ic = inertia_constants(big_a, big_b, big_c)
    n = times.shape[0]
    out = np.empty((n, 3, 3))
    mo, flip = motion_from_momentum(momentum[0], momentum[1], momentum[2], ic)
    if mo[MO_MODE] == MODE_UNIFORM:
        for i in range(n):
            out[i] = uniform_rotation(attitude, momentum, big_a, big_b, big_c, times[i])
        return out
    elements, flip, _ = elements_from_state(attitude, momentum, ic)
    mk, pk = elliptic_constants(mo)
    big_z, big_h, s0, z, h = elements[1], elements[2], elements[3], elements[4], elements[5]
    sin_i = math.sqrt(max((big_z - big_h) * (big_z + big_h), 0.0)) / big_z
    frame = node_frame(big_h / big_z, sin_i, h)
    fx, fy, fz = flip_signs(flip)
    for i in range(n):
        s = s0 + mo[MO_S_RATE] * times[i]
        arg = s * mo[MO_ARG_PER_S]
        mx, my, mz, sin_l, cos_l = body_from_argument(arg, mo, mk)
        g = z + mo[MO_G_PER_S] * s + mo[MO_PN_COEFF] * pn_k(arg, mk, pk)
        sin_j = math.hypot(mx, my) / big_z
        cos_j = mz / big_z
        cg, sg = math.cos(g), math.sin(g)
        # W R3(g) with W = R3(l) R1(J), written out: rows of the body axes in the node frame.
        w0 = (cos_l, sin_l * cos_j, sin_l * sin_j)
        w1 = (-sin_l, cos_l * cos_j, cos_l * sin_j)
        w2 = (0.0, -sin_j, cos_j)
        m = np.empty((3, 3))
        for row, w, sign in ((0, w0, fx), (1, w1, fy), (2, w2, fz)):
            m[row, 0] = sign * (w[0] * cg - w[1] * sg)
            m[row, 1] = sign * (w[0] * sg + w[1] * cg)
            m[row, 2] = sign * w[2]
        out[i] = m @ frame
    return out
