"""The node frame of a torque-free state, and g0: from the attitude and the body momentum, no matrix.

The set-up of the flow (:mod:`.flow_constants`) needs the node frame R1(I) R3(h) as a quaternion and
the Andoyer angle g at t = 0. :func:`node_of_state` forms them for one state; its regular case
(J ≠ 0, I ≠ 0: every state off two measure-zero sets) is written as plain arithmetic
(:func:`node_rotations`, :func:`node_arguments`), which :mod:`.flow_blocks` runs for eight states at
once in ``Lanes`` before each lane's atan2, with the same results bit for bit.
"""

import math

from spinorbit.core.jit import INLINE, jit


@jit
def half_angles(sin_x, cos_x):
    """(cos(x/2), sin(x/2)) for x ∈ (−π, π] from (sin x, cos x) on the unit circle, no cancellation."""
    if cos_x >= 0.0:
        ch = math.sqrt(0.5 * (1.0 + cos_x))
        return ch, sin_x / (2.0 * ch)
    sh = math.copysign(math.sqrt(0.5 * (1.0 - cos_x)), sin_x)
    return sin_x / (2.0 * sh), sh


@jit
def node_quaternion(cos_i, sin_i, sin_h, cos_h):
    """Quaternion (w, x, y, z) of the node frame (R1(I) R3(h))ᵀ = R3(h)ᵀ R1(I)ᵀ, body → inertial.

    q_z(h) ⊗ q_x(I) from the half angles (:func:`half_angles`, no trigonometric call), as four floats: the matrix of
    :func:`.andoyer.node_frame` and Shepperd's conversion of it allocated two arrays and cost
    ≈ 80 ns of the set-up. The sign is the one :func:`.rotations.matrix_to_quat` picks (largest
    component positive), so the output quaternions keep their sign convention.
    """
    ci, si = half_angles(sin_i, cos_i)  # I ∈ [0, π]
    ch, sh = half_angles(sin_h, cos_h)
    w, x, y, z = ch * ci, ch * si, sh * si, sh * ci
    big = w
    if abs(x) > abs(big):
        big = x
    if abs(y) > abs(big):
        big = y
    if abs(z) > abs(big):
        big = z
    if big < 0.0:
        return -w, -x, -y, -z
    return w, x, y, z


@jit(inline=INLINE)
def rotate(w, x, y, z, vx, vy, vz):
    """M(q) v for a unit quaternion q = (w, x, y, z): the body vector v in the inertial frame."""
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz),
            vz + w * tz + (x * ty - y * tx))


@jit(inline=INLINE)
def node_of_state(quaternion, m0x, m0y, m0z, fx, fy, fz, mx, my):
    """(g0, node quaternion) of a state: :func:`.canonical.node_angles_of` from the quaternion.

    l is the body-frame longitude of the momentum, (sin l, cos l) = (M_x, M_y)/|M_⊥| (working frame;
    at J = 0 the elements' convention l = π/2 of :func:`.canonical.body_from_sncndn`). The inertial
    momentum is M(q) M0 (the flip is its own inverse), the node's h enters only through
    (sin h, cos h) = (i_0, −i_1)/|i_⊥|, and the first row of R3(g) = Wᵀ R Nᵀ needs the inertial
    image of W's first column (cos l, −sin l, 0) in the working frame. No matrix, no atan2 for h,
    no sn, cn, dn at arg0 (≈ 150 ns of the set-up).
    """
    # sums of squares, not hypot (≈ 15 ns each): momenta below 1e150 cannot overflow them
    perp2 = mx * mx + my * my
    if perp2 > 0.0:
        inv = 1.0 / math.sqrt(perp2)
        sin_l, cos_l = mx * inv, my * inv
    else:  # J = 0 (SAM with M_x = M_y = 0)
        sin_l, cos_l = 1.0, 0.0
    i0, i1, big_h, r0, r1, r2, inv_g, across = node_rotations(
        quaternion[0], quaternion[1], quaternion[2], quaternion[3], m0x, m0y, m0z, fx, fy, sin_l, cos_l)
    if across > 0.0:
        inv = 1.0 / across
        sh, ch = i0 * inv, -i1 * inv
    else:  # I = 0: h = atan2(i0, −i1) of the signed zeros, as node_angles_of takes it
        h = math.atan2(i0, -i1)
        sh, ch = math.sin(h), math.cos(h)
    g_y, g_x, cos_i, sin_i = node_arguments(big_h, r0, r1, r2, inv_g, across, sh, ch)
    return math.atan2(g_y, g_x), node_quaternion(cos_i, sin_i, sh, ch)


@jit(inline=INLINE)
def node_rotations(w, x, y, z, m0x, m0y, m0z, fx, fy, sin_l, cos_l):
    """(i0, i1, H, r0, r1, r2, 1/G, |i_⊥|): the inertial momentum M(q) M0, the inertial image of
    (f_x cos l, −f_y sin l, 0), 1/|M0| and the momentum's distance from the inertial z axis."""
    i0, i1, big_h = rotate(w, x, y, z, m0x, m0y, m0z)
    r0, r1, r2 = rotate(w, x, y, z, fx * cos_l, -fy * sin_l, 0.0)
    inv_g = 1.0 / math.sqrt(m0x * m0x + m0y * m0y + m0z * m0z)
    across = math.sqrt(i0 * i0 + i1 * i1)
    return i0, i1, big_h, r0, r1, r2, inv_g, across


@jit(inline=INLINE)
def node_arguments(big_h, r0, r1, r2, inv_g, across, sh, ch):
    """(y, x) with g0 = atan2(y, x) (the first row of R3(g)), and (cos I, sin I)."""
    sin_i, cos_i = across * inv_g, big_h * inv_g
    r3g_00 = r0 * ch + r1 * sh
    r3g_01 = cos_i * (r1 * ch - r0 * sh) + sin_i * r2
    return r3g_01, r3g_00, cos_i, sin_i
