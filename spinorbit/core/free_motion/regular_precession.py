"""The torque-free motion of an axisymmetric body in closed form: regular precession, trig only.

With two equal principal moments the Jacobi functions of eq. (12) reduce to sin and cos (elliptic
parameter 0) and the motion is a regular precession. With e the unit symmetry axis (body frame),
I_s the moment about it, I_t the other two, M the body angular momentum, G = |M| and M_∥ = M·e,
the body angular velocity ω = I⁻¹M splits as

    ω = (G / I_t) m̂ + λ e,     m̂ = M / G,     λ = M_∥ (1/I_s − 1/I_t),

and the motion is the composition of a uniform rotation at Ω = G / I_t about the fixed inertial
direction n of the angular momentum and one at λ about the body axis e:

    q(t) = (cos(Ω t/2), sin(Ω t/2) n) ⊗ q0 ⊗ (cos(λ t/2), sin(λ t/2) e),
    M(t) = M_∥ e + R_e(−λ t) M_⊥(0)    (the body momentum turns about e at −λ).

Proof: with q = Q_L q0 Q_R, q̇ = ½ (0, Ω n) ⊗ q + ½ q ⊗ (0, λ e) = ½ q ⊗ (0, Ω q*nq + λ e), and
q* n q = m̂(t) because Q_L commutes with n; so the body rate is Ω m̂ + λ e = I⁻¹M (Euler's
equations Ṁ = M × ω = λ M × e give the body momentum above). Prolate (I_s < I_t, λ M_∥ > 0) and
oblate (I_s > I_t) bodies, both senses of M_∥, spin exactly along e (M_⊥ = 0) and perpendicular to
it (λ = 0, a uniform rotation) are the same formula; so is a sphere (λ = 0).

Long spans: Ω/2 and λ/2 are double-doubles formed from the exact double inputs (G² from error-free
squares, 1/I_s − 1/I_t from the moments' difference, ``ddouble``), the two half angles are carried
in double-double and reduced modulo 2π before they are rounded (as in :mod:`.torque_free`), so the
phase does not pick up ε·|rate·t|. What remains are roundings of bounded quantities (n, q0, the
products): a constant ε-level error, measured in ``tests/test_regular_precession.py``.

Per evaluation: two sin/cos pairs, two quaternion products, no elliptic function and no Π (the
elliptic path spends one sn/cn/dn and one Carlson Π per time). Conventions: quaternions scalar
first, body → inertial (``docs/conventions.md``); principal axes A ≤ B ≤ C, symmetry axis A when
B = C, C when A = B.
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.math.ddouble import (
    TWO_PI_HI,
    TWO_PI_LO,
    dd_add,
    dd_difference_ratio,
    dd_div,
    dd_mul,
    dd_remainder,
    dd_scale,
    dd_sqrt,
    two_prod,
)
from spinorbit.core.math.rotations import qmul_parts

NO_SYMMETRY_AXIS = -1

# Indices into the per-state constants of a regular precession (precession_constants).
(
    PC_AXIS,  # index of the symmetry axis e in the principal frame: 0 (B = C) or 2 (A = B)
    PC_HALF_OMEGA_HI,  # Ω/2 = G/(2 I_t): half-angle rate about the inertial momentum direction n
    PC_HALF_OMEGA_LO,
    PC_HALF_LAMBDA_HI,  # λ/2 = M_∥ (1/I_s − 1/I_t)/2: half-angle rate about the body axis e
    PC_HALF_LAMBDA_LO,
    PC_N_X,  # n, unit angular momentum in the inertial frame
    PC_N_Y,
    PC_N_Z,
    PC_Q0_W,  # attitude at t = 0 (scalar first, body → inertial)
    PC_Q0_X,
    PC_Q0_Y,
    PC_Q0_Z,
    PC_M_PAR,  # M_∥, constant
    PC_M_U,  # the two transverse body momentum components at t = 0, in cyclic order after the axis
    PC_M_V,
) = range(15)
PRECESSION_SIZE = 15


@jit
def symmetry_axis(big_a, big_b, big_c):
    """Principal index of the symmetry axis: 0 if B = C, 2 if A = B (a sphere too), else −1.

    Equality is exact: a body whose moments differ by one ulp is triaxial and takes the elliptic
    flow (no approximation is made here).
    """
    if big_a == big_b:
        return 2
    if big_b == big_c:
        return 0
    return NO_SYMMETRY_AXIS


@jit
def precession_constants(quaternion, momentum, big_a, big_b, big_c, axis):
    """The constants of the regular precession through one state (computed once per state).

    Parameters
    ----------
    quaternion : (4,) ndarray
        Attitude at t = 0, scalar first, body → inertial (unit norm).
    momentum : (3,) ndarray
        Body angular momentum at t = 0 in principal axes (mass·length²/time), not all zero.
    big_a, big_b, big_c : float
        Principal moments A ≤ B ≤ C with two of them equal (mass·length²).
    axis : int
        :func:`symmetry_axis` of the moments (0 or 2).

    Returns
    -------
    (PRECESSION_SIZE,) ndarray
        The ``PC_*`` constants.
    """
    pc = np.zeros(PRECESSION_SIZE)
    big_s = big_a if axis == 0 else big_c
    big_t = big_b
    u, v = (axis + 1) % 3, (axis + 2) % 3
    x2h, x2l = two_prod(momentum[0], momentum[0])
    y2h, y2l = two_prod(momentum[1], momentum[1])
    z2h, z2l = two_prod(momentum[2], momentum[2])
    g2h, g2l = dd_add(x2h, x2l, y2h, y2l)
    g2h, g2l = dd_add(g2h, g2l, z2h, z2l)
    gh, gl = dd_sqrt(g2h, g2l)
    oh, ol = dd_div(gh, gl, 2.0 * big_t, 0.0)
    rh, rl = dd_difference_ratio(big_s, big_t)  # 1/I_s − 1/I_t, from I_t − I_s
    lh, ll = dd_mul(0.5 * momentum[axis], 0.0, rh, rl)
    pc[PC_AXIS] = axis
    pc[PC_HALF_OMEGA_HI], pc[PC_HALF_OMEGA_LO] = oh, ol
    pc[PC_HALF_LAMBDA_HI], pc[PC_HALF_LAMBDA_LO] = lh, ll
    # n = M(q0) m̂0: the body unit momentum rotated to the inertial frame, (q0 ⊗ (0, m̂) ⊗ q0*)
    big_g = gh + gl
    w0, x0, y0, z0 = quaternion[0], quaternion[1], quaternion[2], quaternion[3]
    t = qmul_parts(w0, x0, y0, z0, 0.0, momentum[0] / big_g, momentum[1] / big_g, momentum[2] / big_g)
    n = qmul_parts(t[0], t[1], t[2], t[3], w0, -x0, -y0, -z0)
    pc[PC_N_X], pc[PC_N_Y], pc[PC_N_Z] = n[1], n[2], n[3]
    pc[PC_Q0_W], pc[PC_Q0_X], pc[PC_Q0_Y], pc[PC_Q0_Z] = w0, x0, y0, z0
    pc[PC_M_PAR], pc[PC_M_U], pc[PC_M_V] = momentum[axis], momentum[u], momentum[v]
    return pc


@jit
def _half_angle(rate_hi, rate_lo, t):
    """(cos, sin) of rate·t with the product in double-double and reduced modulo 2π first."""
    ph, pl = dd_scale(rate_hi, rate_lo, t)
    _, r = dd_remainder(ph, pl, TWO_PI_HI, TWO_PI_LO)
    return math.cos(r), math.sin(r)


@jit
def evaluate_precession(t, pc, q_out, m_out):
    """Attitude and body momentum at time t of the regular precession described by ``pc``.

    Writes q_out[0:4] (scalar first, body → inertial) and m_out[0:3] (principal-axis body momentum).
    """
    axis = int(pc[PC_AXIS])
    ca, sa = _half_angle(pc[PC_HALF_OMEGA_HI], pc[PC_HALF_OMEGA_LO], t)
    cb, sb = _half_angle(pc[PC_HALF_LAMBDA_HI], pc[PC_HALF_LAMBDA_LO], t)
    left = qmul_parts(ca, sa * pc[PC_N_X], sa * pc[PC_N_Y], sa * pc[PC_N_Z],
                      pc[PC_Q0_W], pc[PC_Q0_X], pc[PC_Q0_Y], pc[PC_Q0_Z])
    ex = sb if axis == 0 else 0.0
    ez = sb if axis == 2 else 0.0
    q = qmul_parts(left[0], left[1], left[2], left[3], cb, ex, 0.0, ez)
    q_out[0], q_out[1], q_out[2], q_out[3] = q
    # cos λt, sin λt from the half angle (no second reduction, no cancellation in 1 − 2 sin²)
    c, s = (cb - sb) * (cb + sb), 2.0 * sb * cb
    mu, mv = pc[PC_M_U], pc[PC_M_V]
    m_out[axis] = pc[PC_M_PAR]
    m_out[(axis + 1) % 3] = mu * c + mv * s
    m_out[(axis + 2) % 3] = mv * c - mu * s
