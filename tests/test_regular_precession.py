"""The closed-form free flow of axisymmetric bodies (``spinorbit.core.free_motion.regular_precession``).

Two independent references:

* the elliptic flow of ``torque_free`` at parameter 0 (``closed_forms=False``), itself validated
  against heyoka and a 40-digit reference in ``test_torque_free.py``;
* a 40-digit mpmath evaluation of the textbook Euler-angle form of regular precession (Goldstein
  §5.6; Landau–Lifshitz §33), a different construction from the quaternion product of the kernel:
  in a frame F whose z axis is the angular momentum, the body frame with its third axis on the
  symmetry axis is R3(ψ) R1(θ) R3(φ) F with cos θ = M_∥/G, φ̇ = G/I_t, ψ̇ = M_∥ (1/I_s − 1/I_t);
  φ0, ψ0 are read from the initial attitude in 40 digits, the rates from the exact double inputs.
"""

import math

import mpmath as mp
import numpy as np
import pytest

from _heyoka_reference import rotation_angle
from spinorbit.core.free_motion.regular_precession import NO_SYMMETRY_AXIS, symmetry_axis
from spinorbit.core.math.rotations import quat_to_attitude
from spinorbit.core.free_motion.flow import torque_free_attitudes, torque_free_states, torque_free_states_many

# Against the 40-digit Euler-angle reference: what is left is the rounding of the quaternion products
# q_L ⊗ q0 ⊗ q_R, of the inertial direction n and of the reduced half angles (bounded, a few ε); no
# growth with t because the rates and phases are double-double. Measured ≤ 1.4e-15 rad (momentum
# ≤ 4.5e-16 G) over the 16 cases below at every time up to t = 1e9 (≈ 1.6e8 turns), with no trend
# in t; 4e-15 leaves room for other states (a quaternion product of three rounded factors).
MP_TOLERANCE = 4e-15  # rad (and relative to G for the momentum)
# Against the elliptic flow at parameter 0: both paths are ε-level against their references, so
# their difference is the sum of two such errors (measured ≤ 1.5e-15 rad, 5.2e-16 G, to t = 1e7).
ELLIPTIC_TOLERANCE = 4e-15  # rad (and relative to G)
TILTED = np.array([0.9, 0.1, -0.3, 0.2]) / math.sqrt(0.95)
LONG_TIMES = np.array([0.3, 17.1, 1e3 + 0.1, 1e5 + 0.7, 1e7 + 0.3, 1e9 + 0.9])

OBLATE = (1.0, 1.0, 2.0)  # A = B < C: symmetry axis C
PROLATE = (0.5, 1.0, 1.0)  # A < B = C: symmetry axis A
MOMENTA = {
    "generic": [0.3, 0.4, 0.8],
    "generic, other sense": [-0.3, 0.4, -0.8],
    "along C": [0.0, 0.0, 1.0],
    "along -A": [-1.0, 0.0, 0.0],
    "in the A-B plane": [0.6, -0.8, 0.0],
    "along B": [0.0, 0.7, 0.0],
    "1e-8 from C": [1e-8, 0.0, 1.0],
    "1e-8 from the B-C plane": [1e-8, 0.3, 1.0],
}
CASES = [(body, label) for body in ("oblate", "prolate") for label in MOMENTA]


def _mp_rot1(x):
    c, s = mp.cos(x), mp.sin(x)
    return mp.matrix([[1, 0, 0], [0, c, s], [0, -s, c]])


def _mp_rot3(x):
    c, s = mp.cos(x), mp.sin(x)
    return mp.matrix([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def _mp_attitude(q):
    """Attitude matrix R = M(q)ᵀ (inertial → body) of a scalar-first quaternion, normalized in mp."""
    w, x, y, z = (mp.mpf(float(v)) for v in q)
    norm = mp.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    m = mp.matrix([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])
    return m.T


def euler_reference(quaternion, momentum, moments, times, dps=40):
    """(attitude matrices, body momenta) from the Euler-angle form of regular precession (mpmath)."""
    axis = symmetry_axis(*moments)
    with mp.workdps(dps):
        big_s, big_t = mp.mpf(moments[axis]), mp.mpf(moments[1])
        m0 = mp.matrix([mp.mpf(float(v)) for v in momentum])
        big_g = mp.sqrt(sum(v * v for v in m0))
        r0 = _mp_attitude(quaternion)
        n = r0.T * m0 / big_g  # inertial unit momentum
        # F: inertial → frame with z on n (any x ⟂ n)
        helper = mp.matrix([1, 0, 0]) if abs(n[0]) < 0.9 else mp.matrix([0, 1, 0])
        fx = helper - (helper.T * n)[0] * n
        fx = fx / mp.norm(fx)
        fy = mp.matrix([n[1] * fx[2] - n[2] * fx[1], n[2] * fx[0] - n[0] * fx[2], n[0] * fx[1] - n[1] * fx[0]])
        frame = mp.matrix([[fx[0], fx[1], fx[2]], [fy[0], fy[1], fy[2]], [n[0], n[1], n[2]]])
        # P: principal body frame → frame B' with its third axis on the symmetry axis (cyclic, proper)
        order = [(axis + 1) % 3, (axis + 2) % 3, axis]
        perm = mp.matrix(3, 3)
        for row, col in enumerate(order):
            perm[row, col] = 1
        e = perm * r0 * frame.T  # = R3(ψ0) R1(θ) R3(φ0)
        sin_theta = mp.sqrt(e[2, 0] ** 2 + e[2, 1] ** 2)
        theta = mp.atan2(sin_theta, e[2, 2])
        if sin_theta > mp.mpf(10) ** (-dps // 2 - 5):  # an exact axis gives ~1e-40 here, not 0
            phi0, psi0 = mp.atan2(e[2, 0], -e[2, 1]), mp.atan2(e[0, 2], e[1, 2])
        else:  # spin along the symmetry axis: only φ + ψ is defined
            phi0, psi0 = mp.mpf(0), mp.atan2(e[0, 1], e[0, 0]) * (1 if e[2, 2] > 0 else -1)
        phi_dot = big_g / big_t
        psi_dot = m0[axis] * (1 / big_s - 1 / big_t)
        attitudes, momenta = [], []
        for t in times:
            tt = mp.mpf(float(t))
            r = perm.T * _mp_rot3(psi0 + psi_dot * tt) * _mp_rot1(theta) * _mp_rot3(phi0 + phi_dot * tt) * frame
            attitudes.append(np.array([[float(r[i, j]) for j in range(3)] for i in range(3)]))
            mb = r * n * big_g
            momenta.append([float(mb[i]) for i in range(3)])
    return np.array(attitudes), np.array(momenta)


def attitude_angle(r1, r2):
    """Rotation angle (rad) between stacks of attitude matrices, from the antisymmetric part (small angles)."""
    d = np.einsum("kij,klj->kil", r1, r2)
    skew = 0.5 * np.stack([d[:, 2, 1] - d[:, 1, 2], d[:, 0, 2] - d[:, 2, 0], d[:, 1, 0] - d[:, 0, 1]], axis=1)
    return np.linalg.norm(skew, axis=1)


def _case(body, label):
    return (OBLATE if body == "oblate" else PROLATE), np.array(MOMENTA[label], dtype=float)


@pytest.mark.parametrize("body, label", CASES, ids=[f"{b}: {lab}" for b, lab in CASES])
def test_closed_form_matches_the_euler_angle_reference_to_a_billion_time_units(body, label):
    moments, momentum = _case(body, label)
    q, m = torque_free_states(TILTED, momentum, *moments, LONG_TIMES)
    attitudes_ref, momenta_ref = euler_reference(TILTED, momentum, moments, LONG_TIMES)
    r = np.array([quat_to_attitude(x) for x in q])
    assert attitude_angle(r, attitudes_ref).max() < MP_TOLERANCE
    assert np.abs(m - momenta_ref).max() < MP_TOLERANCE * np.linalg.norm(momentum)


@pytest.mark.parametrize("body, label", CASES, ids=[f"{b}: {lab}" for b, lab in CASES])
def test_closed_form_matches_the_elliptic_flow(body, label):
    moments, momentum = _case(body, label)
    times = LONG_TIMES[:-1]
    q, m = torque_free_states(TILTED, momentum, *moments, times)
    q_ell, m_ell = torque_free_states(TILTED, momentum, *moments, times, closed_forms=False)
    assert rotation_angle(q, q_ell).max() < ELLIPTIC_TOLERANCE
    assert np.abs(m - m_ell).max() < ELLIPTIC_TOLERANCE * np.linalg.norm(momentum)


def test_the_closed_form_is_what_runs_for_symmetric_bodies_only():
    assert symmetry_axis(*OBLATE) == 2 and symmetry_axis(*PROLATE) == 0 and symmetry_axis(1.0, 1.0, 1.0) == 2
    assert symmetry_axis(1.0, math.nextafter(1.0, 2.0), 2.0) == NO_SYMMETRY_AXIS
    # the two paths differ in their last bits: equal outputs would mean the dispatch did nothing
    momentum = np.array(MOMENTA["generic"])
    q, _ = torque_free_states(TILTED, momentum, *PROLATE, LONG_TIMES[:4])
    q_ell, _ = torque_free_states(TILTED, momentum, *PROLATE, LONG_TIMES[:4], closed_forms=False)
    assert not np.array_equal(q, q_ell)


def test_matrix_form_and_many_states_take_the_closed_form_too():
    rng = np.random.default_rng(7)
    quaternions = rng.normal(size=(5, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    momenta = rng.normal(size=(5, 3))
    moments = np.array([OBLATE, PROLATE, OBLATE, PROLATE, (0.61, 0.965, 1.0)])
    times = LONG_TIMES[:4]
    q, m = torque_free_states_many(quaternions, momenta, moments, times)
    for i in range(5):
        qi, mi = torque_free_states(quaternions[i], momenta[i], *moments[i], times)
        np.testing.assert_array_equal(q[i], qi)
        np.testing.assert_array_equal(m[i], mi)
        r = torque_free_attitudes(quat_to_attitude(quaternions[i]), momenta[i], *moments[i], times)
        # the matrix form enters through attitude_to_quat (a few ε; measured ≤ 1.2e-15 rad)
        assert attitude_angle(r, np.array([quat_to_attitude(x) for x in qi])).max() < 4e-15


def test_invariants_and_initial_state():
    momentum = np.array(MOMENTA["generic"])
    for moments in (OBLATE, PROLATE):
        q, m = torque_free_states(TILTED, momentum, *moments, np.r_[0.0, LONG_TIMES])
        assert rotation_angle(q[:1], TILTED[None]).max() < 1e-16
        np.testing.assert_allclose(np.linalg.norm(m, axis=1), np.linalg.norm(momentum), rtol=4e-16)
        energy = np.sum(m**2 / np.array(moments), axis=1)
        np.testing.assert_allclose(energy, energy[0], rtol=8e-16)
        # the inertial angular momentum stays fixed
        inertial = np.einsum("kji,kj->ki", np.array([quat_to_attitude(x) for x in q]), m)
        assert np.abs(inertial - inertial[0]).max() < 4e-15
