"""The "de421" Moon model's faster DE421 sampling changes no bit: the compiled Chebyshev sums against
jplephem's own (real DE421), the grid rule's scalar interpolation against numpy's."""

import numpy as np
import pytest

from spinorbit.coupling.sampling import _scalar_interp
from spinorbit.ephemeris import _ephemeris, chebyshev_sums
from spinorbit.time import J2000_JD_TDB


@pytest.mark.parametrize("series", ["moon", "earthmoon", "sun", "venus", "mars", "jupiter", "saturn", "librations"])
def test_chebyshev_sums_equal_jplephem_bit_for_bit(series):
    ephemeris = _ephemeris()
    rng = np.random.default_rng(7)
    whole = J2000_JD_TDB + np.round(rng.uniform(-30000.0, 30000.0, 4000))
    fraction = rng.uniform(-0.5, 0.5, whole.size)
    expected_position, expected_rate = ephemeris.position_and_velocity(series, whole, fraction)
    coefficients, days_per_set, chebyshev, twice_t = ephemeris.compute_bundle(series, whole, fraction)
    position, rate = chebyshev_sums(np.ascontiguousarray(coefficients), np.ascontiguousarray(chebyshev),
                                    np.ascontiguousarray(twice_t), float(days_per_set))
    np.testing.assert_array_equal(position, expected_position)
    np.testing.assert_array_equal(rate, expected_rate)


def test_scalar_interp_equals_numpy_interp_bit_for_bit():
    rng = np.random.default_rng(3)
    nodes = np.sort(rng.uniform(-10.0, 400.0, 1500))
    values = rng.uniform(0.01, 5.0, nodes.size)
    interpolate = _scalar_interp(nodes, values)
    points = np.concatenate([rng.uniform(-20.0, 420.0, 20000), nodes, [nodes[0], nodes[-1]]])
    ours = np.array([interpolate(float(x)) for x in points])
    np.testing.assert_array_equal(ours, np.interp(points, nodes, values))


def test_moon_orientation_equals_the_scalar_kernels_bit_for_bit():
    """The compiled loop of moon_orientation_raw against the scalar kernels called one time at a time."""
    import math

    from spinorbit.core.math.rotations import attitude_to_quat_many, euler313_rates_to_omega, euler313_to_attitude
    from spinorbit.ephemeris import moon_libration_angles_raw, moon_orientation_raw

    rng = np.random.default_rng(11)
    day = np.round(rng.uniform(-30000.0, 30000.0, 300))
    fraction = rng.uniform(-0.5, 0.5, day.size)
    angles, rates = moon_libration_angles_raw(day, fraction)
    attitudes, omega = np.empty((day.size, 3, 3)), np.empty((day.size, 3))
    for i, ((phi, theta, psi), (phi_dot, theta_dot, psi_dot)) in enumerate(zip(angles, rates)):
        psi = math.remainder(psi, 2.0 * math.pi)
        attitudes[i] = euler313_to_attitude(phi, theta, psi)
        omega[i] = euler313_rates_to_omega(phi, theta, psi, phi_dot, theta_dot, psi_dot)
    quaternion, omega_fast = moon_orientation_raw(day, fraction)
    np.testing.assert_array_equal(quaternion, attitude_to_quat_many(attitudes))
    np.testing.assert_array_equal(omega_fast, omega)
