"""The symplectic splitting integrator: orders, energy behaviour, invariants, ε-scaling, agreement.

Test problem: the Hairer–Lubich–Wanner body I = (2, 1, 2/3), principal A = 2/3, B = 1, C = 2, body
momentum (sin 1.1, 0, cos 1.1) (|ω| ≈ 1.36, one rotation ≈ 4.6 time units), torqued by a point mass
at rest at R = (1, 0.3, 0.5) (time-independent, so E = T − U is conserved). The size of the
perturbation is set by the perturber's μ.
"""

import math

import numpy as np
import pytest

from spinorbit.core.dynamics.equations import inertial_angular_momentum, make_model, total_energy
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.integrators.splitting import SCHEMES, integrate_splitting
from spinorbit.core.model.perturbers import fixed_source
from spinorbit.core.math.rotations import rotation_angle_between_many
from spinorbit.core.free_motion.flow import torque_free_states

MOMENTS = (2.0 / 3.0, 1.0, 2.0)
BODY_MOMENTUM = np.array([math.sin(1.1), 0.0, math.cos(1.1)])
Y0 = np.concatenate([[1.0, 0.0, 0.0, 0.0], BODY_MOMENTUM / np.array(MOMENTS)])
PERTURBER_AT = np.array([1.0, 0.3, 0.5])

#: Reference accuracy: DOP853 at rtol 1e-14 over 10 time units is good to ~1e-13 rad; every error
#: used for an order below is ≥ 1e-11, so the reference contributes < 1 %.
REFERENCE_RTOL = 1e-14
ORDER_SPAN = 10.0
#: Measured slopes must lie within this distance of the theoretical order (pre-asymptotic terms).
ORDER_TOLERANCE = 0.25
#: The weak-torque orders are measured with long steps (up to a fifth of a rotation), further from the
#: asymptotic regime: a wider window.
WEAK_ORDER_TOLERANCE = 0.6


def model_with(mu):
    return make_model(MOMENTS, [fixed_source(mu, PERTURBER_AT)] if mu else [])


def attitude_error(ys, ref):
    return float(rotation_angle_between_many(np.ascontiguousarray(ys[:, :4]), np.ascontiguousarray(ref[:, :4])).max())


def measured_orders(scheme, mu, steps):
    model = model_with(mu)
    ref = integrate_quaternion(Y0, 0.0, [ORDER_SPAN], model, rtol=REFERENCE_RTOL, atol=1e-16)
    errors = np.array([attitude_error(integrate_splitting(Y0, 0.0, [ORDER_SPAN], model, h, scheme), ref)
                       for h in steps])
    return errors, np.log(errors[:-1] / errors[1:]) / np.log(np.asarray(steps[:-1]) / np.asarray(steps[1:]))


# ---------------------------------------------------------------------------------------------- order

#: Strong torque (μ = 1e-1: torque/spin-rate² ≈ 0.2): every scheme shows its nominal order, which for
#: the SABA/SBAB family is 2 (the ε² τ² term).
STRONG_MU = 1e-1
#: Weak torque: the ε τ^{2n} term dominates over the tested steps, so SABA2/SBAB2 show 4, SABA3 shows 6.
#: For SABA3 the crossover ε τ⁶ = ε² τ² is at τ ≈ ε^{1/4}: μ = 1e-5 puts it near 0.05, below the
#: steps (1, 0.5, 0.25), whose errors (1.5e-9 … 2.3e-13) stay above the reference's ~1e-14.
WEAK_MU = {"saba2": 1e-6, "sbab2": 1e-6, "saba3": 1e-5}


@pytest.mark.parametrize("scheme", sorted(SCHEMES))
def test_nominal_order_with_a_strong_torque(scheme):
    expected = {"strang": 2, "yoshida4": 4, "yoshida6": 6, "saba2": 2, "saba3": 2, "saba4": 2, "sbab2": 2}[scheme]
    steps = {2: (0.05, 0.025, 0.0125), 4: (0.2, 0.1, 0.05), 6: (0.4, 0.2, 0.1)}[expected]
    errors, orders = measured_orders(scheme, STRONG_MU, steps)
    assert errors.min() > 1e-11, errors  # well above the reference's own error
    assert np.all(np.abs(orders - expected) < ORDER_TOLERANCE), (errors, orders)


@pytest.mark.parametrize("scheme", sorted(WEAK_MU))
def test_weak_torque_order_of_the_saba_family(scheme):
    expected = {"saba2": 4, "sbab2": 4, "saba3": 6}[scheme]
    steps = (1.0, 0.5, 0.25)
    errors, orders = measured_orders(scheme, WEAK_MU[scheme], steps)
    assert errors.min() > 1e-13, errors
    # the largest step (τ = 1, a fifth of a rotation) is pre-asymptotic: measured 4.39 then 4.08 for SABA2
    assert np.all(np.abs(orders - expected) < WEAK_ORDER_TOLERANCE), (errors, orders)


def test_weak_torque_order_of_saba4_is_at_least_eight():
    """SABA4's ε τ⁸ term is visible only in a narrow window in double precision: at μ = 1e-6 the
    steps (1.6, 1.2, 0.9) give 8.6e-11 … 3.9e-13 rad with local orders 9.33, 9.47 (the ε τ¹⁰ terms
    still add), smaller steps fall to the ε² τ² term and rounding. So the test asks for ≥ 8 − 0.4
    and ≤ 10 rather than a two-sided window around 8."""
    errors, orders = measured_orders("saba4", 1e-6, (1.6, 1.2, 0.9))
    assert errors.min() > 1e-13, errors
    assert np.all((orders > 7.6) & (orders < 10.0)), (errors, orders)


# ---------------------------------------------------------------------------------- ε-scaling

def test_error_scales_with_the_torque_as_laskar_robutel_predict():
    """SABA2 error ≈ a ε τ⁴ + b ε² τ²: at fixed τ, ∝ ε for weak torques and ∝ ε² for strong ones.

    Strang has only O(ε τ²) at leading order: ∝ ε throughout. Hence for weak torques SABA2 buys
    much longer steps than Strang at the same accuracy.
    """
    step = 0.5
    mus = np.array([1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 3e-2, 1e-1])
    saba2 = []
    strang = []
    for mu in mus:
        model = model_with(mu)
        ref = integrate_quaternion(Y0, 0.0, [ORDER_SPAN], model, rtol=REFERENCE_RTOL, atol=1e-16)
        saba2.append(attitude_error(integrate_splitting(Y0, 0.0, [ORDER_SPAN], model, step, "saba2"), ref))
        strang.append(attitude_error(integrate_splitting(Y0, 0.0, [ORDER_SPAN], model, step, "strang"), ref))
    saba2, strang = np.array(saba2), np.array(strang)
    weak = slice(0, 5)  # μ ≤ 1e-3
    # Strang: linear in ε over the weak range (measured slopes 0.997 … 1.000)
    assert np.all(np.abs(np.diff(np.log10(strang[weak])) / np.diff(np.log10(mus[weak])) - 1.0) < 0.05), strang
    # SABA2: linear in ε while ε τ⁴ dominates (measured 0.9999 … 1.017) …
    assert np.all(np.abs(np.diff(np.log10(saba2[weak])) / np.diff(np.log10(mus[weak])) - 1.0) < 0.05), saba2
    # … and what exceeds the linear part grows like ε² (measured slope 2.07 between μ = 0.03 and 0.1)
    linear = saba2[0] / mus[0]
    excess = saba2[-2:] - linear * mus[-2:]
    assert abs(math.log(excess[1] / excess[0]) / math.log(mus[-1] / mus[-2]) - 2.0) < 0.15, saba2
    # weak torque: SABA2 at τ = 0.5 beats Strang at the same step by two orders of magnitude (measured 76×)
    assert saba2[0] < 2e-2 * strang[0]


# ------------------------------------------------------------------------------------- invariants

TORQUE_FREE_ROUNDOFF_RAD = 1e-12


def test_torque_free_drift_is_the_exact_flow():
    """No perturber: every step is one exact torque-free evaluation; the result matches the closed
    form from t = 0 to rounding and conserves L to rounding.

    Each drift goes through the elements and back; applied as an absolute state that round trip cost
    ≈ 5e-15 rad per drift, growing linearly (4.9e-12 rad after 1000 drifts). Applied as a relative
    rotation (``drift``) the common error cancels: measured 2.1e-13 rad after 1000 drifts; bound 1e-12.
    """
    model = model_with(0.0)
    times = np.linspace(10.0, 100.0, 10)
    ys = integrate_splitting(Y0, 0.0, times, model, 0.1, "saba2")
    q_ref, m_ref = torque_free_states(Y0[:4], BODY_MOMENTUM, *MOMENTS, times)
    assert attitude_error(ys, q_ref) < TORQUE_FREE_ROUNDOFF_RAD
    np.testing.assert_allclose(ys[:, 4:] * np.array(MOMENTS), m_ref, atol=TORQUE_FREE_ROUNDOFF_RAD)
    l0 = inertial_angular_momentum(Y0, model)
    for y in ys:
        np.testing.assert_allclose(inertial_angular_momentum(y, model), l0, atol=1e-13)


def test_fixed_perturber_conserves_the_momentum_along_its_direction_only():
    """A point mass at rest exerts an inertial torque ⊥ its direction, so L·R̂ is conserved (exactly:
    each kick adds τ N ⊥ R̂, each drift conserves L), while L itself is not."""
    mu = 1e-3
    model = model_with(mu)
    times = np.linspace(10.0, 1000.0, 100)
    ys = integrate_splitting(Y0, 0.0, times, model, 0.2, "saba2")
    direction = PERTURBER_AT / np.linalg.norm(PERTURBER_AT)
    l0 = inertial_angular_momentum(Y0, model)
    along = np.array([inertial_angular_momentum(y, model) @ direction for y in ys])
    assert np.max(np.abs(along - l0 @ direction)) < 1e-12
    change = max(np.linalg.norm(inertial_angular_momentum(y, model) - l0) for y in ys)
    assert change > 1e-4  # the torque does change L, by O(μ)


#: Energy test: μ = 1e-3, τ = 0.1 (≈ 46 steps per rotation), SABA2. The splitting conserves a modified
#: energy within O(ε τ⁴ + ε² τ²) of E; measured max |ΔE|/|E| = 2.56e-10 over 1e5 steps and 2.71e-10
#: over 1e6 steps (docs/splitting.md). Bound with a factor ~4.
ENERGY_MU = 1e-3
ENERGY_STEP = 0.1
ENERGY_BOUND = 1e-9


def energy_errors(n_steps, scheme="saba2"):
    model = model_with(ENERGY_MU)
    n_out = 1000
    times = np.linspace(0.0, n_steps * ENERGY_STEP, n_out + 1)[1:]
    ys, stats = integrate_splitting(Y0, 0.0, times, model, ENERGY_STEP, scheme, return_stats=True)
    assert stats["steps"] == n_steps
    e0 = total_energy(0.0, Y0, model)
    return np.array([total_energy(t, y, model) - e0 for t, y in zip(times, ys)]) / abs(e0)


def assert_bounded_without_drift(rel):
    half = rel.size // 2
    assert np.max(np.abs(rel)) < ENERGY_BOUND
    # no secular growth: the second half is no worse than the first (a linear drift would double it)
    assert np.max(np.abs(rel[half:])) < 1.5 * np.max(np.abs(rel[:half]))
    # and the mean does not move: a drift would show as a trend of the half means
    assert abs(rel[half:].mean() - rel[:half].mean()) < 0.2 * np.max(np.abs(rel))


def test_energy_error_bounded_over_1e5_steps():
    assert_bounded_without_drift(energy_errors(100_000))


@pytest.mark.slow
def test_energy_error_bounded_over_1e6_steps():
    assert_bounded_without_drift(energy_errors(1_000_000))


# -------------------------------------------------------------------------------------- scenes

#: Agreement with DOP853 (rtol 1e-14, landing on the output times) on scenes (a) (SABA3, τ = 0.1 day,
#: measured 5e-10 rad) and (b) (SABA2, τ = 0.04 day, measured 1.4e-10 rad over ±60 days).
SCENE_RUNS = {"a": ("saba3", 0.1), "b": ("saba2", 0.04)}
SCENE_TOLERANCE_RAD = 1e-9


@pytest.mark.parametrize("name", ["a", "b"])
def test_agrees_with_dop853_on_the_benchmark_scenes(name):
    from benchmarks.scenes import scene_apophis, scene_toutatis

    scene = scene_apophis() if name == "a" else scene_toutatis(half_span=30.0)
    ref = integrate_quaternion(scene.y0, scene.t0, scene.t_out, scene.model, rtol=1e-14, hit_output_times=True)
    scheme, step = SCENE_RUNS[name]
    ys = integrate_splitting(scene.y0, scene.t0, scene.t_out, scene.model, step, scheme)
    assert attitude_error(ys, ref) < SCENE_TOLERANCE_RAD
    np.testing.assert_allclose(ys[:, 4:], ref[:, 4:], atol=SCENE_TOLERANCE_RAD * np.abs(scene.y0[4:]).max())


# ------------------------------------------------------------------------------ outputs, validation

def test_lands_on_output_times_and_counts_merged_drifts():
    model = model_with(1e-3)
    times = [0.3, 1.0, 1.05]
    ys, stats = integrate_splitting(Y0, 0.0, times, model, 0.1, "saba2", return_stats=True)
    assert stats["steps"] == 3 + 7 + 1  # ceil(0.3/0.1) (no extra step for rounding), 7, 1
    # SABA2: 2 kicks per step; drifts merged across steps: 2 per step + 1 per output interval
    assert stats["kicks"] == 2 * 11 and stats["drifts"] == 2 * 11 + 3
    # output at t = 1.0 equals a run that stops there
    alone = integrate_splitting(Y0, 0.0, [1.0], model, 0.1, "saba2")
    assert attitude_error(ys[1:2], alone) < 1e-6  # different step sequence: same O(τ⁴ε) accuracy


def test_backward_integration_returns_to_the_start():
    model = model_with(1e-3)
    forward = integrate_splitting(Y0, 0.0, [5.0], model, 0.1, "yoshida4")[0]
    back = integrate_splitting(forward, 5.0, [0.0], model, 0.1, "yoshida4")[0]
    # symmetric schemes: the step with −τ inverts the step with τ (to rounding)
    assert attitude_error(back[None], Y0[None]) < 1e-12
    np.testing.assert_allclose(back[4:], Y0[4:], atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(step=0.0), "step: expected a finite step > 0"),
        (dict(step=float("nan")), "step: expected a finite step > 0"),
        (dict(step="x"), "step: expected a positive number"),
        (dict(step=0.1, scheme="rk4"), "scheme: expected one of"),
        (dict(step=0.1, t_out=[]), "t_out: expected a non-empty"),
        (dict(step=0.1, t_out=[2.0, 1.0]), "t_out: expected output times strictly"),
    ],
)
def test_input_errors_name_the_parameter(kwargs, match):
    args = dict(y0=Y0, t0=0.0, t_out=[1.0], model=model_with(1e-3))
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        integrate_splitting(**args)


def test_unordered_moments_are_refused():
    model = make_model(MOMENTS)
    model[0], model[1] = model[1], model[0]  # make_model itself refuses this; a hand-edited array
    with pytest.raises(ValueError, match="model: expected principal moments 0 < A ≤ B ≤ C"):
        integrate_splitting(Y0, 0.0, [1.0], model, 0.1)


@pytest.mark.parametrize("moments", [MOMENTS, (0.61, 0.965, 1.0), (0.5, 0.999, 1.0), (0.999, 1.0, 2.0)])
def test_short_drift_setup_equals_the_double_double_one(moments):
    """The double-precision drift setup gives the same drift as the double-double one: measured
    ≤ 2e-14 rad / relative momentum over 2000 random states and |τ| ≤ 3 (nearly symmetric bodies
    included); bound 1e-13."""
    from spinorbit.core.integrators.splitting import DRIFT_SCRATCH_SIZE, drift

    scratch = np.empty(DRIFT_SCRATCH_SIZE)
    rng = np.random.default_rng(7)
    for _ in range(200):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        m = rng.normal(size=3)
        tau = rng.uniform(-3.0, 3.0)
        q1, m1, q2, m2 = q.copy(), m.copy(), q.copy(), m.copy()
        drift(tau, q1, m1, *moments, True, scratch)
        drift(tau, q2, m2, *moments, False, scratch)
        assert attitude_error(q1[None], q2[None]) < 1e-13
        np.testing.assert_allclose(m1, m2, atol=1e-13 * np.linalg.norm(m))


def test_both_drift_setups_give_the_same_run():
    model = model_with(1e-3)
    short = integrate_splitting(Y0, 0.0, [50.0], model, 0.1, "saba2", free_flow_setup="short")
    long = integrate_splitting(Y0, 0.0, [50.0], model, 0.1, "saba2", free_flow_setup="long")
    assert attitude_error(short, long) < 1e-11
    with pytest.raises(ValueError, match="free_flow_setup: expected 'short' or 'long'"):
        integrate_splitting(Y0, 0.0, [1.0], model, 0.1, free_flow_setup="fast")
