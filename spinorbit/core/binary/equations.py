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
contact distance, both inertia tensors and their inverses, and both tables of inertia integrals.
"""

import math

import numpy as np

from spinorbit.core.binary.inertia_integrals import INTEGRALS_SIZE, inertia_tensor, rotate_integrals
from spinorbit.core.binary.monomials import DEGREE_START, MAX_ORDER, N_MONOMIALS
from spinorbit.core.binary.mutual_potential import mutual_field, torque_from_weights
from spinorbit.core.jit import jit
from spinorbit.core.math.rotations import quat_to_matrix

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
BINARY_MODEL_SIZE = M_INTEGRALS_B + INTEGRALS_SIZE


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


@jit
def unit_quaternion_matrix(y, offset):
    """M(q/|q|) of the quaternion at y[offset:offset + 4] (the RHS sees only the direction of q)."""
    norm = math.sqrt(y[offset] ** 2 + y[offset + 1] ** 2 + y[offset + 2] ** 2 + y[offset + 3] ** 2)
    q = np.empty(4)
    for i in range(4):
        q[i] = y[offset + i] / norm
    return quat_to_matrix(q)


@jit
def mutual_state(y, model):
    """(U, ∂U/∂R inertial, N_A on A's axes, N_B on B's axes, R_A) of the state y: the one field evaluation."""
    order = int(model[M_ORDER])
    m_a = unit_quaternion_matrix(y, QUAT_A)
    m_b = unit_quaternion_matrix(y, QUAT_B)
    c = m_a.T @ m_b
    r_a = m_a.T @ y[POSITION:POSITION + 3]
    integrals_a = model[M_INTEGRALS_A:M_INTEGRALS_A + INTEGRALS_SIZE]
    rotated_b = np.empty(INTEGRALS_SIZE)
    rotate_integrals(model[M_INTEGRALS_B:M_INTEGRALS_B + INTEGRALS_SIZE], c, order, rotated_b)
    derivatives = np.empty(N_MONOMIALS)
    weights_a = np.empty(INTEGRALS_SIZE)
    weights_b = np.empty(INTEGRALS_SIZE)
    u, gx, gy, gz = mutual_field(r_a[0], r_a[1], r_a[2], model[M_G], integrals_a, rotated_b, order,
                                 derivatives, weights_a, weights_b)
    grad = m_a @ np.array([gx, gy, gz])
    nax, nay, naz = torque_from_weights(weights_a, integrals_a, order)
    nbx, nby, nbz = torque_from_weights(weights_b, rotated_b, order)
    torque_b = c.T @ np.array([nbx, nby, nbz])
    return u, grad, np.array([nax, nay, naz]), torque_b, r_a


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
def euler_rate_into(y, w_offset, model, inertia_offset, torque, out):
    """ω̇ = I⁻¹((I ω) × ω + N) for a full inertia tensor I (row-major at inertia_offset, inverse after it)."""
    wx, wy, wz = y[w_offset], y[w_offset + 1], y[w_offset + 2]
    i = inertia_offset
    lx = model[i] * wx + model[i + 1] * wy + model[i + 2] * wz
    ly = model[i + 3] * wx + model[i + 4] * wy + model[i + 5] * wz
    lz = model[i + 6] * wx + model[i + 7] * wy + model[i + 8] * wz
    bx = ly * wz - lz * wy + torque[0]
    by = lz * wx - lx * wz + torque[1]
    bz = lx * wy - ly * wx + torque[2]
    v = inertia_offset + 9
    out[w_offset] = model[v] * bx + model[v + 1] * by + model[v + 2] * bz
    out[w_offset + 1] = model[v + 3] * bx + model[v + 4] * by + model[v + 5] * bz
    out[w_offset + 2] = model[v + 6] * bx + model[v + 7] * by + model[v + 8] * bz


@jit
def binary_rhs_into(t, y, model, out):
    """dy/dt of the full two-body problem into out; returns |R| − contact distance (< 0: in contact)."""
    _, grad, torque_a, torque_b, _ = mutual_state(y, model)
    inverse_reduced_mass = 1.0 / model[M_MASS_A] + 1.0 / model[M_MASS_B]
    for i in range(3):
        out[POSITION + i] = y[VELOCITY + i]
        out[VELOCITY + i] = inverse_reduced_mass * grad[i]
    quaternion_rate_into(y, QUAT_A, OMEGA_A, out)
    quaternion_rate_into(y, QUAT_B, OMEGA_B, out)
    euler_rate_into(y, OMEGA_A, model, M_INERTIA_A, torque_a, out)
    euler_rate_into(y, OMEGA_B, model, M_INERTIA_B, torque_b, out)
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


#: The order bound the tables were built for (re-exported for the front ends' checks).
SUPPORTED_ORDER = MAX_ORDER
#: Scratch sizes of one field evaluation (for callers that evaluate many states).
FIELD_SCRATCH = (N_MONOMIALS, int(DEGREE_START[MAX_ORDER + 1]))
