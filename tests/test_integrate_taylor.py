"""The numba Taylor-series integrator: one definition of the physics, accuracy, order, bad input."""

import math

import numpy as np
import pytest

from spinorbit.core.errors import WorkLimitError

from spinorbit.core.dynamics.equations import inertial_angular_momentum, make_model, rhs, total_energy
from spinorbit.core.integrators.quaternion import IntegrationError, integrate_quaternion
from spinorbit.core.integrators.taylor import (
    TaylorFallbackWarning,
    integrate_taylor,
    integrate_taylor_fixed_step,
    taylor_series,
)
from spinorbit.core.model.perturbers import fixed_source, kepler_source, kepler_state, sampled_source
from spinorbit.core.math.rotations import rotation_angle_between

TRIAXIAL = (0.61, 0.965, 1.0)
Y0 = np.array([0.9, 0.1, -0.3, 0.2, 0.4, -1.1, 2.3])
Y0[:4] /= np.linalg.norm(Y0[:4])

#: y^[1] and rhs_into evaluate the same formulas in a different order (the body-frame position as
#: r + 2(u × c − q₀ c) instead of the rotation matrix): they differ by rounding, a few ulps of the
#: largest term.
FIRST_COEFFICIENT_RTOL = 1e-13
#: 2 y^[2] against the central difference of rhs along the flow with step δ = 1e-5: truncation
#: ~δ² |y'''| ≈ 1e-10 and rounding ~ε/δ ≈ 1e-11, relative to the largest component.
SECOND_COEFFICIENT_RTOL = 1e-8
#: Invariant drift allowed after ~100 rotations at tol 1e-14 (≈ 1700 steps of local error ≤ 1e-14
#: plus the renormalisation's rounding).
INVARIANT_RTOL = 1e-11
#: Fixed-step order window: an order-p Taylor method converges with order p; pre-asymptotic rows
#: measured here are within ±0.3 of p.
ORDER_WINDOW = 0.4


def _kepler_elliptic():
    return kepler_source(30.0, 4.0, 0.3, 0.4, 0.5, 0.6, 0.7)


def _kepler_hyperbolic():
    return kepler_source(2.0, -0.5, 3.0, 0.2, 1.1, -0.4, -1.5)


def _sampled_orbit(t_lo=-2.0, t_hi=30.0, n=400):
    orbit = _kepler_elliptic()
    times = np.linspace(t_lo, t_hi, n)
    states = np.array([kepler_state(t, orbit.params) for t in times])
    return sampled_source(30.0, times, states[:, :3], states[:, 3:])


def _all_kinds_model():
    return make_model(TRIAXIAL, [_kepler_elliptic(), _kepler_hyperbolic(), fixed_source(5.0, [1.0, 2.0, -3.0]),
                                 _sampled_orbit()])


def _random_unit_states(rng, n):
    ys = rng.normal(size=(n, 7))
    ys[:, :4] /= np.linalg.norm(ys[:, :4], axis=1)[:, None]
    return ys


def test_first_coefficient_is_the_right_hand_side():
    """y^[1] = f(t, y): the recurrences are dynamics.rhs_into term by term (one definition)."""
    rng = np.random.default_rng(4)
    model = _all_kinds_model()
    for y in _random_unit_states(rng, 20):
        t = rng.uniform(0.0, 25.0)
        series = taylor_series(t, y, model, 6)
        f = rhs(t, y, model)
        np.testing.assert_allclose(series[:, 0], y, rtol=0, atol=4e-16)  # taylor_series re-normalises q
        np.testing.assert_allclose(series[:, 1], f, rtol=0, atol=FIRST_COEFFICIENT_RTOL * np.abs(f).max())


def test_second_coefficient_is_the_derivative_of_the_right_hand_side_along_the_flow():
    """2 y^[2] = d/dt f(t, y(t)) = ∂f/∂t + (∂f/∂y) f: checks the product/power recurrences and the
    perturbers' own series (Kepler two-body ODE, sampled cubic) beyond order 1."""
    rng = np.random.default_rng(5)
    model = _all_kinds_model()
    delta = 1e-5
    for y in _random_unit_states(rng, 10):
        t = rng.uniform(0.0, 25.0)
        series = taylor_series(t, y, model, 6)
        f = rhs(t, y, model)
        df = (rhs(t + delta, y + delta * f, model) - rhs(t - delta, y - delta * f, model)) / (2 * delta)
        np.testing.assert_allclose(2 * series[:, 2], df, rtol=0, atol=SECOND_COEFFICIENT_RTOL * np.abs(df).max())


def test_torque_free_invariants():
    model = make_model(TRIAXIAL)
    t_out = np.linspace(0, 300.0, 7)[1:]  # ~100 rotations at |ω| ≈ 2.6
    ys = integrate_taylor(Y0, 0.0, t_out, model, tol=1e-14)
    l0 = inertial_angular_momentum(Y0, model)
    e0 = total_energy(0.0, Y0, model)
    for y in ys:
        assert np.linalg.norm(inertial_angular_momentum(y, model) - l0) < INVARIANT_RTOL * np.linalg.norm(l0)
        assert abs(total_energy(0.0, y, model) - e0) < INVARIANT_RTOL * abs(e0)
        assert abs(np.linalg.norm(y[:4]) - 1.0) < 4e-16


def test_energy_is_conserved_with_a_perturber_at_rest():
    """E = T − U is exact for a fixed perturber (dynamics.py): the torque series is tested by it."""
    model = make_model(TRIAXIAL, [fixed_source(40.0, [2.0, -1.0, 1.5])])
    ys = integrate_taylor(Y0, 0.0, np.linspace(0, 100.0, 5)[1:], model, tol=1e-14)
    e0 = total_energy(0.0, Y0, model)
    for y in ys:
        assert abs(total_energy(0.0, y, model) - e0) < INVARIANT_RTOL * abs(e0)


@pytest.mark.validation
@pytest.mark.parametrize("scene_name", ["a", "b"])
def test_accuracy_against_extended_precision_heyoka(scene_name):
    """Short pieces of the benchmark scenes against heyoka in 80-bit long double at tol 1.1e-19
    (benchmarks/peers.reference_solution): an independent implementation in higher precision.

    Scene (a) over 20 d (≈ 18 rotations, ≈ 110 steps), scene (b) the ±5 d around the 0.01 AU flyby.
    At tol 1e-14 the error is local error × steps plus rounding: allowed 1e-11 rad. The error must
    also fall with the tolerance (local error control works): tol 1e-8 → 1e-11 → 1e-14 each ≥ 10×
    better until the 1e-12 floor.
    """
    import dataclasses

    from benchmarks.peers import reference_solution
    from benchmarks.scenes import scene_apophis, scene_toutatis

    if scene_name == "a":
        scene = scene_apophis()
        scene = dataclasses.replace(scene, t_out=np.linspace(0.0, 20.0, 5)[1:])
    else:
        scene = scene_toutatis(half_span=5.0)
    reference, _ = reference_solution(scene)
    errors = []
    for tol in (1e-8, 1e-11, 1e-14):
        ys = integrate_taylor(scene.y0, scene.t0, scene.t_out, scene.model, tol=tol)
        errors.append(max(rotation_angle_between(a[:4], b[:4]) for a, b in zip(ys, reference)))
        np.testing.assert_allclose(ys[:, 4:], reference[:, 4:], atol=100 * errors[-1] * np.abs(scene.y0[4:]).max()
                                   + 1e-12 * np.abs(scene.y0[4:]).max())
    assert errors[-1] < 1e-11, errors
    assert errors[0] > 10 * errors[1] or errors[0] < 1e-11, errors
    assert errors[1] > 10 * errors[2] or errors[1] < 1e-11, errors


def test_matches_dop853_with_kepler_and_fixed_perturbers():
    """Kepler (elliptic, hyperbolic) and fixed perturbers together against the DOP853 integrator at
    rtol 1e-14 landing on the output times (two methods, the same rhs_into). The hyperbolic one passes
    at 1 length unit and makes the attitude sensitive: DOP853 at 1e-13 and 1e-14 differ by 3e-10 rad
    after 20 time units, so 1e-9 rad is allowed."""
    model = make_model(TRIAXIAL, [_kepler_elliptic(), _kepler_hyperbolic(), fixed_source(5.0, [1.0, 2.0, -3.0])])
    t_out = np.linspace(0.0, 20.0, 6)[1:]
    ours = integrate_taylor(Y0, 0.0, t_out, model, tol=1e-14)
    theirs = integrate_quaternion(Y0, 0.0, t_out, model, rtol=1e-14, hit_output_times=True)
    for a, b in zip(ours, theirs):
        assert rotation_angle_between(a[:4], b[:4]) < 1e-9


def test_sampled_perturber_reproduces_kepler_run():
    """Hermite samples of an orbit give the Kepler run's attitude up to the interpolation error, which
    falls ×16 per halving of the spacing (fourth order). Taylor steps are clipped at the sample times,
    where the piecewise cubic has a jump in its second derivative."""
    orbit = _kepler_elliptic()
    reference = integrate_taylor(Y0, 0.0, [20.0], make_model(TRIAXIAL, [orbit]), tol=1e-14)[0]
    errors = []
    for n in (400, 800):
        sampled = integrate_taylor(Y0, 0.0, [20.0], make_model(TRIAXIAL, [_sampled_orbit(n=n)]), tol=1e-14)[0]
        errors.append(rotation_angle_between(sampled[:4], reference[:4]))
    assert errors[0] < 1e-5
    assert 10 < errors[0] / errors[1] < 25, errors


def test_backward_integration_with_a_sampled_perturber_returns_to_start():
    """Backwards the steps are clipped at the sample times below t, as forwards above it."""
    model = make_model(TRIAXIAL, [_sampled_orbit()])
    y1 = integrate_taylor(Y0, 0.0, [8.0], model, tol=1e-14)[0]
    y0_back = integrate_taylor(y1, 8.0, [0.0], model, tol=1e-14)[0]
    assert rotation_angle_between(y0_back[:4], Y0[:4]) < 1e-11
    np.testing.assert_allclose(y0_back[4:], Y0[4:], atol=1e-11 * np.linalg.norm(Y0[4:]))


def test_dense_output_matches_separate_runs():
    """Output times inside a step come from the Taylor polynomial; integrating to each time in a
    separate run (landing on it) gives the same state to the local error."""
    model = make_model(TRIAXIAL, [_kepler_elliptic()])
    t_out = np.array([0.37, 1.91, 4.2])
    dense = integrate_taylor(Y0, 0.0, t_out, model, tol=1e-14)
    for t, y in zip(t_out, dense):
        alone = integrate_taylor(Y0, 0.0, [t], model, tol=1e-14)[0]
        assert rotation_angle_between(alone[:4], y[:4]) < 1e-12


@pytest.mark.parametrize("order", [4, 6, 8])
def test_fixed_step_order_equals_taylor_order(order):
    model = make_model(TRIAXIAL, [_kepler_elliptic()])
    reference = integrate_taylor(Y0, 0.0, [6.0], model, tol=1e-16)[0]
    steps = (60, 120, 240) if order < 8 else (30, 60, 120)
    errors = [rotation_angle_between(integrate_taylor_fixed_step(Y0, 0.0, 6.0, n, model, order)[:4], reference[:4])
              for n in steps]
    measured = math.log2(errors[-2] / errors[-1])
    assert abs(measured - order) < ORDER_WINDOW, (errors, measured)


def test_stats_report_order_from_tolerance():
    model = make_model(TRIAXIAL, [_kepler_elliptic()])
    _, stats = integrate_taylor(Y0, 0.0, [5.0], model, tol=1e-10, return_stats=True)
    assert stats["order"] == math.ceil(-math.log(1e-10) / 2 + 1)  # heyoka's rule: 13
    assert stats["steps"] > 0
    assert 0 < stats["mean_orbit_order"] <= stats["order"]


def test_degree_three_field_falls_back_to_dop853_with_a_warning():
    stokes_c = np.zeros((4, 4))
    stokes_c[3, 0] = 1e-3
    model = make_model(TRIAXIAL, [_kepler_elliptic()], mass=1.0, stokes_c=stokes_c, stokes_s=np.zeros((4, 4)))
    with pytest.warns(TaylorFallbackWarning, match="degree-3"):
        ys = integrate_taylor(Y0, 0.0, [1.0], model, tol=1e-12)
    expected = integrate_quaternion(Y0, 0.0, [1.0], model, rtol=1e-12)
    np.testing.assert_array_equal(ys, expected)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(y0=[np.nan, 0, 0, 0, 1, 0, 0]), "finite"),
        (dict(y0=[0, 0, 0, 0, 1, 0, 0]), "non-zero quaternion"),
        (dict(t_out=[1.0, 0.5]), "strictly increasing"),
        (dict(tol=0.0), "tol: expected a tolerance > 0"),
        (dict(tol=1e-17), "tol ≥ 1e-16"),
        (dict(tol=float("nan")), "tol"),
        (dict(order_factor=0.5), "order_factor"),
        (dict(order_factor=3.0), "order_factor"),
    ],
)
def test_bad_input_raises_value_error(kwargs, match):
    args = dict(y0=Y0, t0=0.0, t_out=[1.0, 2.0], model=make_model(TRIAXIAL), tol=1e-10)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        integrate_taylor(**args)


def test_sampled_perturber_outside_its_span_is_refused():
    model = make_model(TRIAXIAL, [_sampled_orbit(0.0, 1.0, 5)])
    with pytest.raises(ValueError, match="sampled perturbers are defined only on"):
        integrate_taylor(Y0, 0.0, [2.0], model)


def test_step_cap_raises_integration_error():
    # Over the cap by the estimate made before starting (issue 14): refused up front, naming max_steps.
    with pytest.raises(WorkLimitError, match="max_steps = 3"):
        integrate_taylor(Y0, 0.0, [100.0], make_model(TRIAXIAL), max_steps=3)
    # Within the estimate (a lower bound, 41 steps here) but over the cap in fact: the kernel stops.
    with pytest.raises(IntegrationError, match="max_steps"):
        integrate_taylor(Y0, 0.0, [100.0], make_model(TRIAXIAL), max_steps=60)


@pytest.mark.parametrize("kwargs, match", [(dict(n_steps=0), "n_steps"), (dict(order=0), "order"),
                                           (dict(order=99), "order")])
def test_fixed_step_bad_input(kwargs, match):
    args = dict(y0=Y0, t0=0.0, t1=1.0, n_steps=10, model=make_model(TRIAXIAL), order=6)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        integrate_taylor_fixed_step(**args)


def test_convergence_radius_is_the_smaller_of_the_two_estimates():
    """The one-power shortcut gives min(n_prev^(−1/(p−1)), n_last^(−1/p)) whichever is smaller, inf for zero norms."""
    from spinorbit.core.integrators.taylor import convergence_radius

    rng = np.random.default_rng(18)
    for _ in range(2000):
        order = int(rng.integers(2, 40))
        n_prev, n_last = 10.0 ** rng.uniform(-30, 5, size=2)
        expected = min(n_prev ** (-1.0 / (order - 1)), n_last ** (-1.0 / order))
        assert convergence_radius(n_prev, n_last, order) == pytest.approx(expected, rel=1e-14)
    assert convergence_radius(0.0, 1e-8, 9) == 1e-8 ** (-1.0 / 9)
    assert convergence_radius(1e-8, 0.0, 9) == 1e-8 ** (-1.0 / 8)
    assert math.isinf(convergence_radius(0.0, 0.0, 9))


@pytest.mark.parametrize("rows", [1, 3, 4, 7, 10])
def test_horner_in_groups_of_four_rows_is_each_rows_polynomial(rows):
    """horner's grouped rows (the last group shifted back, rows < 4 one by one) give each row's own Horner sum."""
    from spinorbit.core.integrators.taylor_recurrences import horner

    rng = np.random.default_rng(rows)
    order, dt = 11, 0.37
    s = rng.normal(size=(rows + 2, order + 1))
    out = np.full(rows, np.nan)
    horner(s, rows, order, dt, out)
    expected = [np.polynomial.polynomial.polyval(dt, s[i]) for i in range(rows)]
    np.testing.assert_allclose(out, expected, rtol=1e-14)
