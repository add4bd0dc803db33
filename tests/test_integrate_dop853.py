"""The DOP853 engine (spinorbit.core.integrators.dop853) on a problem with a known solution.

The harmonic oscillator x'' = −x from (x, v) = (1, 0): x = cos t, v = −sin t. The engine is driven
through its own entry points with a right-hand side defined here, as a new propagator would use it.
"""

import math

import numba
import numpy as np

from spinorbit.core.integrators.dop853 import (
    INTERPOLATOR_POWER,
    N_STAGES,
    N_STAGES_EXTENDED,
    STAT_ACCEPTED,
    STAT_REJECTED,
    STAT_STATUS,
    STATUS_SUCCESS,
    dense_coefficients,
    dense_polynomial,
    dop853_fixed_steps,
    dop853_integrate,
    dop853_stages,
    keep_representation,
    never_singular,
    output_as_is,
)

#: Status code of the test's stop hook (any code the engine does not use itself).
STATUS_BELOW_ZERO = 7


@numba.njit
def oscillator(t, y, omega, out):
    out[0] = y[1]
    out[1] = -omega * omega * y[0]


@numba.njit
def oscillator_reporting_x(t, y, omega, out):
    oscillator(t, y, omega, out)
    return y[0]


@numba.njit
def below_zero(x):
    return STATUS_BELOW_ZERO if x < 0.0 else STATUS_SUCCESS


@numba.njit
def fixed_steps(t1, n_steps):
    y, _ = dop853_fixed_steps(oscillator, 1.0, never_singular, keep_representation, np.array([1.0, 0.0]), 0.0, t1,
                              n_steps)
    return y


@numba.njit
def one_step_dense_output(h, x):
    """The continuous extension of one step of size h from (1, 0), at t = x h."""
    y = np.array([1.0, 0.0])
    k = np.zeros((N_STAGES_EXTENDED, 2))
    tmp = np.empty(2)
    y_new = np.empty(2)
    oscillator(0.0, y, 1.0, k[0])
    dop853_stages(oscillator, 1.0, 0.0, y, h, k, tmp, y_new)
    oscillator(h, y_new, 1.0, k[N_STAGES])
    coeffs = np.zeros((INTERPOLATOR_POWER, 2))
    dense_coefficients(oscillator, 1.0, 0.0, y, y_new, k[N_STAGES].copy(), h, k, tmp, coeffs)
    out = np.empty(2)
    dense_polynomial(coeffs, y, x, out)
    return out


@numba.njit
def adaptive(t_out, rtol, hit_output_times):
    return dop853_integrate(oscillator, 1.0, never_singular, keep_representation, output_as_is,
                            np.array([1.0, 0.0]), 0.0, t_out, rtol, np.full(2, rtol), 10**6, hit_output_times,
                            0.0, 0.0)


@numba.njit
def adaptive_until_below_zero(t_out, rtol):
    return dop853_integrate(oscillator_reporting_x, 1.0, below_zero, keep_representation, output_as_is,
                            np.array([1.0, 0.0]), 0.0, t_out, rtol, np.full(2, rtol), 10**6, False, 0.0, 0.0)


def measured_orders(errors):
    return [math.log2(a / b) for a, b in zip(errors, errors[1:])]


def test_fixed_steps_converge_with_order_8():
    t1 = 8.0
    errors = [abs(fixed_steps(t1, n)[0] - math.cos(t1)) for n in (8, 16, 32)]
    # Measured 8.01, 8.01: the h⁹ term shifts the slope by O(h) only; 0.3 leaves room for it and
    # still tells order 8 from 7 or 9. n = 64 is left out: its error (3e-14) is near rounding.
    assert all(abs(order - 8.0) < 0.3 for order in measured_orders(errors)), errors


def test_dense_output_inside_one_step_has_local_error_of_order_8():
    # The 7th-order continuous extension errs by O(h⁸) inside a step (local error, one step).
    errors = [abs(one_step_dense_output(h, 0.5)[0] - math.cos(0.5 * h)) for h in (1.0, 0.5, 0.25)]
    # Measured 8.04, 8.01 (0.3: as for the fixed steps).
    assert all(abs(order - 8.0) < 0.3 for order in measured_orders(errors)), errors


def test_adaptive_outputs_match_the_exact_solution_with_and_without_landing():
    t_out = np.linspace(0.0, 20.0 * math.pi, 101)[1:]
    for rtol in (1e-8, 1e-10, 1e-12):
        for hit_output_times in (False, True):
            ys, stats, t_stop, _ = adaptive(t_out, rtol, hit_output_times)
            assert stats[STAT_STATUS] == STATUS_SUCCESS and t_stop == t_out[-1]
            error = max(np.abs(ys[:, 0] - np.cos(t_out)).max(), np.abs(ys[:, 1] + np.sin(t_out)).max())
            # The test is local (per step ≤ rtol); over 10 periods the global error measured 0.6–10
            # rtol, dense output and landing alike. 50 rtol: room for that growth, not for a wrong
            # stage, weight or interpolation coefficient (those give errors of h⁴…h⁷, ≫ 1e-6 here).
            assert error < 50 * rtol, (rtol, hit_output_times, error, stats)


def test_status_hook_stops_the_run_at_the_first_step_that_meets_the_set():
    t_out = np.linspace(0.0, 4.0, 9)[1:]
    ys, stats, t_stop, y_stop = adaptive_until_below_zero(t_out, 1e-10)
    assert stats[STAT_STATUS] == STATUS_BELOW_ZERO
    # x = cos t first falls below zero at π/2: the stop is at the end of the step that crossed it,
    # and steps at rtol 1e-10 are ~0.35 long here (178 over 10 periods), so within 0.5 of π/2.
    assert math.pi / 2 < t_stop < math.pi / 2 + 0.5 and y_stop[0] < 0.0
    assert abs(y_stop[0] - math.cos(t_stop)) < 1e-9
    written = t_out <= t_stop
    assert np.isfinite(ys[written]).all() and np.isnan(ys[~written]).all()
    assert stats[STAT_ACCEPTED] > 0 and stats[STAT_REJECTED] >= 0
