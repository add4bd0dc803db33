"""The coupled equations of the full two-body problem: relative orbit and both attitudes and spins.

State (20 floats, named offsets below; ``docs/conventions.md``, "The binary")::

    y[0:3]   R    B's centre of mass relative to A's, inertial axes (length)
    y[3:6]   Ṙ    its velocity (length/time)
    y[6:10]  q_A  A's attitude quaternion, scalar first, body → inertial (v_inertial = M(q_A) v_body)
    y[10:13] ω_A  A's angular velocity on A's body axes (rad/time)
    y[13:17] q_B  B's attitude quaternion
    y[17:20] ω_B  B's angular velocity on B's body axes

Equations (one force function U, :mod:`.mutual_potential`; M_X = M(q_X), C = M_Aᵀ M_B takes B's body
axes to A's):

    R̈ = (1/m_A + 1/m_B) M_A ∂U/∂R_A,         R_A = M_Aᵀ R
    q̇_X = ½ q_X ⊗ (0, ω_X)
    I_A ω̇_A = (I_A ω_A) × ω_A + N_A,         I_B ω̇_B = (I_B ω_B) × ω_B + Cᵀ N_B

with N_A, N_B the torques of :func:`.mutual_potential.torque_from_weights` (N_B on A's axes). The
inertia tensors may be full (any body whose integrals are given on axes that are not principal).

The model is one flat float64 array (:func:`make_binary_model`): G, the order, both masses, the
contact distance, both inertia tensors and their inverses, both tables of inertia integrals, and the
Sun's block (off by default; :func:`with_sun` switches it on): with it, R̈ gains the solar tide and
each Euler equation the Sun's gravity-gradient torque (:mod:`.solar_tide`, degree 2).
"""

import math

import numpy as np

from spinorbit.core.binary.inertia_integrals import INTEGRALS_SIZE, inertia_tensor, rotate_integrals_into
from spinorbit.core.binary.monomials import N_MONOMIALS
from spinorbit.core.binary.mutual_potential import mutual_field, torque_from_weights
from spinorbit.core.binary.solar_tide import gravity_gradient_torque_xyz, sun_position_xyz, tidal_acceleration_xyz
from spinorbit.core.jit import jit
from spinorbit.core.model.perturbers import KIND_KEPLER, PARAM_SIZE

# State layout.
POSITION, VELOCITY, QUAT_A, OMEGA_A, QUAT_B, OMEGA_B = 0, 3, 6, 10, 13, 17
BINARY_STATE_SIZE = 20

# Model layout.
M_G, M_ORDER, M_MASS_A, M_MASS_B, M_CONTACT = 0, 1, 2, 3, 4
M_INERTIA_A = 5
M_INVERSE_A = M_INERTIA_A + 9
M_INERTIA_B = M_INVERSE_A + 9
M_INVERSE_B = M_INERTIA_B + 9
M_INTEGRALS_A = M_INVERSE_B + 9
M_INTEGRALS_B = M_INTEGRALS_A + INTEGRALS_SIZE
# The Sun's block: [switch (1 on, 0 off), μ = G M_sun, Kepler parameter row of perturbers.py].
M_SUN = M_INTEGRALS_B + INTEGRALS_SIZE
M_SUN_MU = M_SUN + 1
M_SUN_ORBIT = M_SUN + 2
BINARY_MODEL_SIZE = M_SUN_ORBIT + PARAM_SIZE


def make_binary_model(g, integrals_a, integrals_b, order, contact_distance):
    """The flat model array of the two bodies.

    Parameters
    ----------
    g : float
        Gravitational constant in the units of the integrals and the state (e.g. 6.6743e-11 m³/(kg s²)).
    integrals_a, integrals_b : ndarray (INTEGRALS_SIZE,)
        Each body's inertia integrals on its own body axes (:mod:`.inertia_integrals`).
    order : int
        Expansion order, 0 ≤ order ≤ MAX_ORDER (checked by the callers in the units layer and
        :func:`spinorbit.core.binary.propagate.check_order`).
    contact_distance : float
        Sum of the circumscribing radii: the expansion diverges below it, and the propagation stops.
    """
    model = np.zeros(BINARY_MODEL_SIZE)
    model[M_G] = g
    model[M_ORDER] = order
    model[M_MASS_A] = integrals_a[0]
    model[M_MASS_B] = integrals_b[0]
    model[M_CONTACT] = contact_distance
    for offset, integrals in ((M_INERTIA_A, integrals_a), (M_INERTIA_B, integrals_b)):
        inertia = inertia_tensor(integrals)
        model[offset:offset + 9] = inertia.ravel()
        model[offset + 9:offset + 18] = np.linalg.inv(inertia).ravel()
    model[M_INTEGRALS_A:M_INTEGRALS_A + INTEGRALS_SIZE] = integrals_a
    model[M_INTEGRALS_B:M_INTEGRALS_B + INTEGRALS_SIZE] = integrals_b
    return model


def with_sun(model, sun):
    """A copy of the model with the Sun's tide on, the barycentre on the orbit of ``sun``.

    Parameters
    ----------
    model : ndarray
        :func:`make_binary_model`.
    sun : perturber source
        :func:`spinorbit.core.model.perturbers.kepler_source` of the Sun relative to the barycentre, in
        the units of the model (μ = G M_sun; epoch in the run's time): from the barycentre's
        heliocentric elements with ``sign=-1``.

    Raises
    ------
    ValueError
        ``sun`` is not a Keplerian source (sampled or fixed ones are not carried by the binary's model).
    """
    if getattr(sun, "kind", None) != KIND_KEPLER:
        raise ValueError(f"sun: expected a Keplerian source from perturbers.kepler_source (the barycentre's "
                         f"heliocentric orbit, sign=-1), got {sun!r}.")
    out = np.array(model, dtype=float)
    out[M_SUN] = 1.0
    out[M_SUN_MU] = sun.mu
    out[M_SUN_ORBIT:M_SUN_ORBIT + PARAM_SIZE] = sun.params
    return out


@jit  # not inlined: a call only when the Sun is on keeps the isolated pair's RHS as compact as before
def solar_terms_into(t, y, model):
    """The Sun's tidal acceleration of R (inertial) and its torques on A and B (each on its own axes).

    Returns 9 floats (ax, ay, az, N_Ax, N_Ay, N_Az, N_Bx, N_By, N_Bz), all zero when the Sun is off.
    """
    if model[M_SUN] == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    mu = model[M_SUN_MU]
    sx, sy, sz = sun_position_xyz(t, model, M_SUN_ORBIT)
    rx, ry, rz = y[POSITION], y[POSITION + 1], y[POSITION + 2]
    ax, ay, az = tidal_acceleration_xyz(mu, sx, sy, sz, rx, ry, rz)
    share_a = model[M_MASS_A] / (model[M_MASS_A] + model[M_MASS_B])  # r_B = share_a R, r_A = (share_a − 1) R
    share_b = share_a - 1.0
    nax, nay, naz = gravity_gradient_torque_xyz(mu, sx - share_b * rx, sy - share_b * ry, sz - share_b * rz,
                                                unit_quaternion_matrix_parts(y, QUAT_A), model, M_INERTIA_A)
    nbx, nby, nbz = gravity_gradient_torque_xyz(mu, sx - share_a * rx, sy - share_a * ry, sz - share_a * rz,
                                                unit_quaternion_matrix_parts(y, QUAT_B), model, M_INERTIA_B)
    return ax, ay, az, nax, nay, naz, nbx, nby, nbz


# Scratch of one field evaluation (one float64 array, allocated once per run: the RHS allocates nothing).
S_ROTATION = 0  # C = M_Aᵀ M_B, row-major
S_ROTATED_B = S_ROTATION + 9  # B's integrals on A's axes
S_DERIVATIVES = S_ROTATED_B + INTEGRALS_SIZE  # ∂^α(1/R), degree ≤ MAX_ORDER + 1
S_WEIGHTS_A = S_DERIVATIVES + N_MONOMIALS
S_WEIGHTS_B = S_WEIGHTS_A + INTEGRALS_SIZE
S_POLY = S_WEIGHTS_B + INTEGRALS_SIZE
S_SPARE = S_POLY + INTEGRALS_SIZE
SCRATCH_SIZE = S_SPARE + INTEGRALS_SIZE


@jit(inline="always")
def unit_quaternion_matrix_parts(y, offset):
    """M(q/|q|) (body → inertial) of the quaternion at y[offset:offset + 4], row-major as a 9-tuple."""
    norm2 = y[offset] ** 2 + y[offset + 1] ** 2 + y[offset + 2] ** 2 + y[offset + 3] ** 2
    w, x, yy, z = y[offset], y[offset + 1], y[offset + 2], y[offset + 3]
    s = 2.0 / norm2  # M(q) for a non-unit q is M(q/|q|) with 2/|q|² in place of 2
    return (1.0 - s * (yy * yy + z * z), s * (x * yy - w * z), s * (x * z + w * yy),
            s * (x * yy + w * z), 1.0 - s * (x * x + z * z), s * (yy * z - w * x),
            s * (x * z - w * yy), s * (yy * z + w * x), 1.0 - s * (x * x + yy * yy))


@jit
def unit_quaternion_matrix(y, offset):
    """M(q/|q|) of the quaternion at y[offset:offset + 4] as a (3, 3) array."""
    parts = unit_quaternion_matrix_parts(y, offset)
    m = np.empty((3, 3))
    for k in range(9):
        m[k // 3, k % 3] = parts[k]
    return m


@jit(inline="always")  # RHS hot path: no call boundary for the arrays to cross
def field_into(y, model, scratch):
    """The one field evaluation of state y: U, ∂U/∂R on the inertial axes, N_A on A's axes, N_B on B's axes.

    Returns the 10 floats (U, gx, gy, gz, N_Ax, N_Ay, N_Az, N_Bx, N_By, N_Bz); ``scratch`` has
    SCRATCH_SIZE floats and is overwritten (nothing is allocated).
    """
    order = int(model[M_ORDER])
    ma = unit_quaternion_matrix_parts(y, QUAT_A)
    mb = unit_quaternion_matrix_parts(y, QUAT_B)
    rx, ry, rz = y[POSITION], y[POSITION + 1], y[POSITION + 2]
    # R on A's axes, M_Aᵀ R, and C = M_Aᵀ M_B (B's axes → A's axes).
    xa = ma[0] * rx + ma[3] * ry + ma[6] * rz
    ya = ma[1] * rx + ma[4] * ry + ma[7] * rz
    za = ma[2] * rx + ma[5] * ry + ma[8] * rz
    rotation = scratch[S_ROTATION:S_ROTATION + 9]
    for k in range(3):
        for j in range(3):
            rotation[3 * k + j] = ma[k] * mb[j] + ma[3 + k] * mb[3 + j] + ma[6 + k] * mb[6 + j]
    integrals_a = model[M_INTEGRALS_A:M_INTEGRALS_A + INTEGRALS_SIZE]
    rotated_b = scratch[S_ROTATED_B:S_ROTATED_B + INTEGRALS_SIZE]
    rotate_integrals_into(model[M_INTEGRALS_B:M_INTEGRALS_B + INTEGRALS_SIZE], rotation, order, rotated_b,
                          scratch[S_POLY:S_POLY + INTEGRALS_SIZE], scratch[S_SPARE:S_SPARE + INTEGRALS_SIZE])
    weights_a = scratch[S_WEIGHTS_A:S_WEIGHTS_A + INTEGRALS_SIZE]
    weights_b = scratch[S_WEIGHTS_B:S_WEIGHTS_B + INTEGRALS_SIZE]
    u, gxa, gya, gza = mutual_field(xa, ya, za, model[M_G], integrals_a, rotated_b, order,
                                    scratch[S_DERIVATIVES:S_DERIVATIVES + N_MONOMIALS], weights_a, weights_b)
    gx = ma[0] * gxa + ma[1] * gya + ma[2] * gza
    gy = ma[3] * gxa + ma[4] * gya + ma[5] * gza
    gz = ma[6] * gxa + ma[7] * gya + ma[8] * gza
    nax, nay, naz = torque_from_weights(weights_a, integrals_a, order)
    tx, ty, tz = torque_from_weights(weights_b, rotated_b, order)
    nbx = rotation[0] * tx + rotation[3] * ty + rotation[6] * tz
    nby = rotation[1] * tx + rotation[4] * ty + rotation[7] * tz
    nbz = rotation[2] * tx + rotation[5] * ty + rotation[8] * tz
    return u, gx, gy, gz, nax, nay, naz, nbx, nby, nbz


@jit
def mutual_state(y, model):
    """(U, ∂U/∂R inertial, N_A on A's axes, N_B on B's axes, R on A's axes) of state y, as arrays.

    The allocating form of :func:`field_into`, for set-up, diagnostics and tests.
    """
    u, gx, gy, gz, nax, nay, naz, nbx, nby, nbz = field_into(y, model, np.zeros(SCRATCH_SIZE))
    m_a = unit_quaternion_matrix(y, QUAT_A)
    return (u, np.array([gx, gy, gz]), np.array([nax, nay, naz]), np.array([nbx, nby, nbz]),
            m_a.T @ y[POSITION:POSITION + 3])


@jit(inline="always")
def quaternion_rate_into(y, q_offset, w_offset, out):
    """q̇ = ½ q ⊗ (0, ω) for the quaternion at q_offset and body ω at w_offset."""
    q0, q1, q2, q3 = y[q_offset], y[q_offset + 1], y[q_offset + 2], y[q_offset + 3]
    wx, wy, wz = y[w_offset], y[w_offset + 1], y[w_offset + 2]
    out[q_offset] = 0.5 * (-q1 * wx - q2 * wy - q3 * wz)
    out[q_offset + 1] = 0.5 * (q0 * wx + q2 * wz - q3 * wy)
    out[q_offset + 2] = 0.5 * (q0 * wy - q1 * wz + q3 * wx)
    out[q_offset + 3] = 0.5 * (q0 * wz + q1 * wy - q2 * wx)


@jit(inline="always")
def euler_rate_into(y, w_offset, model, inertia_offset, nx, ny, nz, out):
    """ω̇ = I⁻¹((I ω) × ω + N) for a full inertia tensor I (row-major at inertia_offset, inverse after it)."""
    wx, wy, wz = y[w_offset], y[w_offset + 1], y[w_offset + 2]
    i = inertia_offset
    lx = model[i] * wx + model[i + 1] * wy + model[i + 2] * wz
    ly = model[i + 3] * wx + model[i + 4] * wy + model[i + 5] * wz
    lz = model[i + 6] * wx + model[i + 7] * wy + model[i + 8] * wz
    bx = ly * wz - lz * wy + nx
    by = lz * wx - lx * wz + ny
    bz = lx * wy - ly * wx + nz
    v = inertia_offset + 9
    out[w_offset] = model[v] * bx + model[v + 1] * by + model[v + 2] * bz
    out[w_offset + 1] = model[v + 3] * bx + model[v + 4] * by + model[v + 5] * bz
    out[w_offset + 2] = model[v + 6] * bx + model[v + 7] * by + model[v + 8] * bz


@jit(inline="always")
def add_inverse_inertia_into(out, w_offset, model, inverse_offset, nx, ny, nz):
    """out[w_offset:w_offset + 3] += I⁻¹ N (I⁻¹ row-major at inverse_offset)."""
    v = inverse_offset
    out[w_offset] += model[v] * nx + model[v + 1] * ny + model[v + 2] * nz
    out[w_offset + 1] += model[v + 3] * nx + model[v + 4] * ny + model[v + 5] * nz
    out[w_offset + 2] += model[v + 6] * nx + model[v + 7] * ny + model[v + 8] * nz


@jit
def binary_rhs_into(t, y, params, out):
    """dy/dt of the full two-body problem into out; returns |R| − contact distance (< 0: in contact).

    ``params`` = (model, scratch of SCRATCH_SIZE floats), built once per run by the kernels of
    :mod:`spinorbit.core.binary.propagate`.
    """
    model, scratch = params
    _, gx, gy, gz, nax, nay, naz, nbx, nby, nbz = field_into(y, model, scratch)
    inverse_reduced_mass = 1.0 / model[M_MASS_A] + 1.0 / model[M_MASS_B]
    for i in range(3):
        out[POSITION + i] = y[VELOCITY + i]
    out[VELOCITY] = inverse_reduced_mass * gx
    out[VELOCITY + 1] = inverse_reduced_mass * gy
    out[VELOCITY + 2] = inverse_reduced_mass * gz
    quaternion_rate_into(y, QUAT_A, OMEGA_A, out)
    quaternion_rate_into(y, QUAT_B, OMEGA_B, out)
    euler_rate_into(y, OMEGA_A, model, M_INERTIA_A, nax, nay, naz, out)
    euler_rate_into(y, OMEGA_B, model, M_INERTIA_B, nbx, nby, nbz, out)
    if model[M_SUN] != 0.0:
        # ω̇ is linear in the torque: the Sun's part is I⁻¹ N_sun added on (the isolated pair pays one test).
        tx, ty, tz, sax, say, saz, sbx, sby, sbz = solar_terms_into(t, y, model)
        out[VELOCITY] += tx
        out[VELOCITY + 1] += ty
        out[VELOCITY + 2] += tz
        add_inverse_inertia_into(out, OMEGA_A, model, M_INVERSE_A, sax, say, saz)
        add_inverse_inertia_into(out, OMEGA_B, model, M_INVERSE_B, sbx, sby, sbz)
    distance = math.sqrt(y[POSITION] ** 2 + y[POSITION + 1] ** 2 + y[POSITION + 2] ** 2)
    return distance - model[M_CONTACT]


@jit
def spin_energy(y, model, w_offset, inertia_offset):
    """½ ω · I ω of one body."""
    acc = 0.0
    for i in range(3):
        for j in range(3):
            acc += y[w_offset + i] * model[inertia_offset + 3 * i + j] * y[w_offset + j]
    return 0.5 * acc


@jit
def binary_energy(y, model):
    """Total energy ½ ν |Ṙ|² + ½ ω_A·I_A ω_A + ½ ω_B·I_B ω_B − U (ν the reduced mass)."""
    u, _, _, _, _ = mutual_state(y, model)
    reduced_mass = 1.0 / (1.0 / model[M_MASS_A] + 1.0 / model[M_MASS_B])
    v2 = y[VELOCITY] ** 2 + y[VELOCITY + 1] ** 2 + y[VELOCITY + 2] ** 2
    return (0.5 * reduced_mass * v2 + spin_energy(y, model, OMEGA_A, M_INERTIA_A)
            + spin_energy(y, model, OMEGA_B, M_INERTIA_B) - u)


@jit
def binary_angular_momentum(y, model):
    """Total angular momentum about the centre of mass, inertial axes: ν R × Ṙ + M_A I_A ω_A + M_B I_B ω_B."""
    reduced_mass = 1.0 / (1.0 / model[M_MASS_A] + 1.0 / model[M_MASS_B])
    r = y[POSITION:POSITION + 3]
    v = y[VELOCITY:VELOCITY + 3]
    out = reduced_mass * np.cross(r, v)
    for q_offset, w_offset, inertia_offset in ((QUAT_A, OMEGA_A, M_INERTIA_A), (QUAT_B, OMEGA_B, M_INERTIA_B)):
        inertia = model[inertia_offset:inertia_offset + 9].reshape(3, 3)
        out += unit_quaternion_matrix(y, q_offset) @ (inertia @ y[w_offset:w_offset + 3])
    return out



@jit
def solar_terms(t, y, model):
    """(tidal acceleration (3,) inertial, N_A (3,) on A's axes, N_B (3,) on B's axes) of the Sun at t, as arrays."""
    ax, ay, az, nax, nay, naz, nbx, nby, nbz = solar_terms_into(t, y, model)
    return np.array([ax, ay, az]), np.array([nax, nay, naz]), np.array([nbx, nby, nbz])


@jit
def tide_power(t, y, model):
    """dE/dt of :func:`binary_energy` under the Sun: ν Ṙ·a + ω_A·N_A + ω_B·N_B (the mutual terms cancel)."""
    acceleration, torque_a, torque_b = solar_terms(t, y, model)
    reduced_mass = 1.0 / (1.0 / model[M_MASS_A] + 1.0 / model[M_MASS_B])
    power = 0.0
    for i in range(3):
        power += (reduced_mass * y[VELOCITY + i] * acceleration[i] + y[OMEGA_A + i] * torque_a[i]
                  + y[OMEGA_B + i] * torque_b[i])
    return power
