"""Rotation algebra on plain floats: quaternions, attitude matrices, 3-1-3 Euler angles.

Conventions (``docs/conventions.md``):

- Quaternions are scalar first, q = (w, x, y, z), Hamilton product.
- q takes the inertial axes to the body axes (active): v_inertial = M(q) v_body, and the
  **attitude matrix** is R = M(q)ᵀ, so that v_body = R v_inertial.
- Passive elementary rotations R1(α), R3(α); 3-1-3 Euler angles (φ, θ, ψ) give R = R3(ψ) R1(θ) R3(φ).
- Kinematics with body angular velocity ω: q̇ = ½ q ⊗ (0, ω).

Scalar kernels (numba) work on length-4 / 3×3 arrays; the ``*_many`` functions loop over a leading
axis so that the vectorized layer never loops in Python.
"""

import math

import numpy as np

from spinorbit.core.jit import jit


@jit
def qmul_parts(a0, a1, a2, a3, b0, b1, b2, b3):
    """Hamilton product a ⊗ b of scalar-first quaternions given as components (no allocation)."""
    return (
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    )


@jit
def quat_multiply(p, q):
    """Hamilton product p ⊗ q of two scalar-first quaternions."""
    out = np.empty(4)
    out[0] = p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3]
    out[1] = p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2]
    out[2] = p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1]
    out[3] = p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0]
    return out


@jit
def quat_conjugate(q):
    """Conjugate (w, −x, −y, −z): the inverse rotation of a unit quaternion."""
    return np.array([q[0], -q[1], -q[2], -q[3]])


@jit
def quat_normalize(q):
    """q / |q|. The caller guarantees |q| > 0 (the public layer validates)."""
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return q / norm


@jit
def quat_to_matrix(q):
    """Hamilton rotation matrix M(q) (body → inertial, active) of a unit quaternion.

    The attitude matrix (inertial → body) is its transpose, see :func:`quat_to_attitude`.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    m = np.empty((3, 3))
    m[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    m[0, 1] = 2.0 * (x * y - w * z)
    m[0, 2] = 2.0 * (x * z + w * y)
    m[1, 0] = 2.0 * (x * y + w * z)
    m[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    m[1, 2] = 2.0 * (y * z - w * x)
    m[2, 0] = 2.0 * (x * z - w * y)
    m[2, 1] = 2.0 * (y * z + w * x)
    m[2, 2] = 1.0 - 2.0 * (x * x + y * y)
    return m


@jit
def quat_to_attitude(q):
    """Attitude matrix R (inertial → body): v_body = R v_inertial."""
    return quat_to_matrix(q).T.copy()


@jit
def matrix_to_quat(m):
    """Unit quaternion with M(q) = m for a proper rotation matrix m (body → inertial).

    Shepperd's method: pick the largest of the four squared components to divide by, so that the
    result is accurate to rounding for every rotation (no division by a small number). Returns the
    representative with the largest component positive.
    """
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    q = np.empty(4)
    if trace >= m[0, 0] and trace >= m[1, 1] and trace >= m[2, 2]:
        w4 = 2.0 * math.sqrt(1.0 + trace)
        q[0] = 0.25 * w4
        q[1] = (m[2, 1] - m[1, 2]) / w4
        q[2] = (m[0, 2] - m[2, 0]) / w4
        q[3] = (m[1, 0] - m[0, 1]) / w4
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        x4 = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q[0] = (m[2, 1] - m[1, 2]) / x4
        q[1] = 0.25 * x4
        q[2] = (m[0, 1] + m[1, 0]) / x4
        q[3] = (m[0, 2] + m[2, 0]) / x4
    elif m[1, 1] >= m[2, 2]:
        y4 = 2.0 * math.sqrt(1.0 - m[0, 0] + m[1, 1] - m[2, 2])
        q[0] = (m[0, 2] - m[2, 0]) / y4
        q[1] = (m[0, 1] + m[1, 0]) / y4
        q[2] = 0.25 * y4
        q[3] = (m[1, 2] + m[2, 1]) / y4
    else:
        z4 = 2.0 * math.sqrt(1.0 - m[0, 0] - m[1, 1] + m[2, 2])
        q[0] = (m[1, 0] - m[0, 1]) / z4
        q[1] = (m[0, 2] + m[2, 0]) / z4
        q[2] = (m[1, 2] + m[2, 1]) / z4
        q[3] = 0.25 * z4
    # q / |q| in place (quat_normalize's arithmetic without its second array)
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    for k in range(4):
        q[k] /= norm
    return q


@jit
def attitude_to_quat(r):
    """Quaternion of an attitude matrix R (inertial → body)."""
    return matrix_to_quat(r.T.copy())


@jit
def rot1(angle):
    """Passive rotation R1(α) about x: [[1,0,0],[0,c,s],[0,−s,c]]."""
    c, s = math.cos(angle), math.sin(angle)
    r = np.zeros((3, 3))
    r[0, 0] = 1.0
    r[1, 1] = c
    r[1, 2] = s
    r[2, 1] = -s
    r[2, 2] = c
    return r


@jit
def rot3(angle):
    """Passive rotation R3(α) about z: [[c,s,0],[−s,c,0],[0,0,1]]."""
    c, s = math.cos(angle), math.sin(angle)
    r = np.zeros((3, 3))
    r[0, 0] = c
    r[0, 1] = s
    r[1, 0] = -s
    r[1, 1] = c
    r[2, 2] = 1.0
    return r


@jit
def euler313_to_attitude(phi, theta, psi):
    """Attitude matrix R = R3(ψ) R1(θ) R3(φ) of passive 3-1-3 Euler angles (radians)."""
    return rot3(psi) @ rot1(theta) @ rot3(phi)


@jit
def attitude_to_euler313(r):
    """3-1-3 angles (φ, θ, ψ) of an attitude matrix, θ ∈ [0, π], φ and ψ in (−π, π].

    With R = R3(ψ) R1(θ) R3(φ): R[2,2] = cos θ and R[0:2,2] = sin θ (sin ψ, cos ψ), while
    R00 + R11 = (1 + cos θ) cos(φ + ψ), R01 − R10 = (1 + cos θ) sin(φ + ψ),
    R00 − R11 = (1 − cos θ) cos(φ − ψ), R01 + R10 = (1 − cos θ) sin(φ − ψ).
    Near θ = 0 only φ + ψ is well defined and near θ = π only φ − ψ, so ψ is taken from its own
    column and φ from whichever combination is well conditioned: the round trip angles → matrix →
    angles → matrix is then exact to rounding even at gimbal lock (θ = 0 or π gives ψ = 0).
    """
    sin_theta = math.hypot(r[0, 2], r[1, 2])
    theta = math.atan2(sin_theta, r[2, 2])
    psi = math.atan2(r[0, 2], r[1, 2]) if sin_theta > 0.0 else 0.0
    if r[2, 2] >= 0.0:
        phi = math.atan2(r[0, 1] - r[1, 0], r[0, 0] + r[1, 1]) - psi
    else:
        phi = math.atan2(r[0, 1] + r[1, 0], r[0, 0] - r[1, 1]) + psi
    phi = math.atan2(math.sin(phi), math.cos(phi))  # back into (−π, π]
    return phi, theta, psi


@jit
def euler313_rates_to_omega(phi, theta, psi, phi_dot, theta_dot, psi_dot):
    """Body angular velocity from 3-1-3 angles and their rates (same time unit as the rates)."""
    out = np.empty(3)
    out[0] = phi_dot * math.sin(theta) * math.sin(psi) + theta_dot * math.cos(psi)
    out[1] = phi_dot * math.sin(theta) * math.cos(psi) - theta_dot * math.sin(psi)
    out[2] = phi_dot * math.cos(theta) + psi_dot
    return out


@jit
def rotation_angle_between(q1, q2):
    """Angle (radians, in [0, π]) of the rotation that takes attitude q1 to attitude q2.

    Computed as 2·atan2(|vector part of q1* ⊗ q2|, |scalar part|), which is accurate for tiny
    angles (where 2·acos would lose half the digits) and indifferent to the sign of q.
    """
    d = quat_multiply(quat_conjugate(q1), q2)
    vec = math.sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3])
    return 2.0 * math.atan2(vec, abs(d[0]))


@jit
def quat_to_attitude_many(q):
    """Attitude matrices of an (N, 4) array of unit quaternions → (N, 3, 3)."""
    n = q.shape[0]
    out = np.empty((n, 3, 3))
    for i in range(n):
        matrix = quat_to_attitude(q[i])
        # Element by element: a whole-row assignment makes numba compile its shape-mismatch message
        # (string formatting, seconds of a first run's compile) into the kernel.
        for j in range(3):
            for k in range(3):
                out[i, j, k] = matrix[j, k]
    return out


@jit
def attitude_to_quat_many(r):
    """Quaternions of an (N, 3, 3) array of attitude matrices → (N, 4)."""
    n = r.shape[0]
    out = np.empty((n, 4))
    for i in range(n):
        quaternion = attitude_to_quat(r[i])
        for j in range(4):  # element by element, as in quat_to_attitude_many
            out[i, j] = quaternion[j]
    return out


@jit
def rotation_angle_between_many(q1, q2):
    """Element-wise :func:`rotation_angle_between` of two (N, 4) arrays → (N,)."""
    n = q1.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = rotation_angle_between(q1[i], q2[i])
    return out
