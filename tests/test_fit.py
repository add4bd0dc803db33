"""spinorbit.fit: the analytic Jacobian, recovery of a synthetic truth, covariance coverage, bad input.

Synthetic truths are the Toutatis state of Takahashi et al. (2013) (``spinorbit.data.asteroids``)
propagated by the exact flow (torque-free) or by DOP853 with a perturber's degree-2 torque; the noise
is Gaussian with the stated σ and a fixed seed, so every test is reproducible.
"""

import warnings

import matplotlib
import numpy as np
import pytest
from astropy import units as u
from astropy.time import TimeDelta

from spinorbit.body import RigidBody
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.free_motion.flow import torque_free_states
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.math.rotations import attitude_to_quat, quat_multiply, quat_to_attitude
from spinorbit.core.model.perturbers import kepler_source
from spinorbit.data.asteroids import TOUTATIS_EPOCH, toutatis_rotation_state
from spinorbit.fit import (
    AttitudeObservation,
    AxisObservation,
    FitNotConvergedError,
    InvalidObservationError,
    ObservationOutsideSpanError,
    PeriodObservation,
    SingularGeometryError,
    SpinRateObservation,
    TooFewObservationsError,
    UnseparatedParametersWarning,
    fit_rotation,
)
from spinorbit.fit.fitter import ResidualModel
from spinorbit.fit.observations import rotation_quaternion
from spinorbit.state import RotationState

matplotlib.use("Agg")

TRUTH = toutatis_rotation_state("ecliptic")
EPOCH = TOUTATIS_EPOCH
BODY = TRUTH.body
P = BODY.to_principal
CORE = TRUTH.core_state()
MOMENTS = np.array(BODY.principal_moments)
TRUE_Z = np.concatenate([np.zeros(3), CORE[4:], MOMENTS[:2] / MOMENTS[2]])
SIGMA = 1.0 * u.deg
#: A perturber whose degree-2 torque turns Toutatis's attitude by up to 23° in 30 d (measured; a test
#: torque, far stronger than the Earth's at its 1992 distance): μ in km³/d² with the moments' C = 3.235.
PERTURBER = kepler_source(3.0e-2, 1.0, 0.1, 0.5, 0.2, 0.3, 0.0)


def user_quaternion(q_principal):
    return attitude_to_quat(np.ascontiguousarray(P.T @ quat_to_attitude(q_principal)))


def true_attitudes(days, torqued=False):
    if not torqued:
        return torque_free_states(CORE[:4], MOMENTS * CORE[4:], *MOMENTS, days)[0]
    out = np.empty((days.size, 4))
    forward = days > 0
    out[~forward] = CORE[:4]
    out[forward] = integrate_quaternion(CORE, 0.0, days[forward], make_model(MOMENTS, [PERTURBER]), rtol=1e-13)[:, :4]
    return out


def attitude_observations(days, rng, torqued=False, sigma=SIGMA):
    q = true_attitudes(days, torqued)
    radians = sigma.to_value(u.rad)
    return [AttitudeObservation(EPOCH + TimeDelta(d * u.day),
                                user_quaternion(quat_multiply(q[k], rotation_quaternion(rng.normal(0, radians, 3)))),
                                sigma) for k, d in enumerate(days)]


def true_spin(day):
    return torque_free_states(CORE[:4], MOMENTS * CORE[4:], *MOMENTS, [day])[1][0] / MOMENTS


def first_guess(rotation_deg=(5.0, -3.0, 4.0), spin_factor=1.03, moments=(3.0, 3.3, 1.0)):
    q = quat_multiply(CORE[:4], rotation_quaternion(np.deg2rad(rotation_deg)))
    return RotationState.from_matrix(RigidBody(list(moments)), P.T @ quat_to_attitude(q),
                                     TRUTH.angular_velocity * spin_factor)


def mixed_observations(rng):
    days = np.linspace(-6.0, 20.0, 20)
    observations = attitude_observations(days, rng)
    q = true_attitudes(np.array([3.0, 11.0]))
    for k, d in enumerate((3.0, 11.0)):
        axis = np.array([0.0, 0.0, 1.0])
        direction = quat_to_attitude(user_quaternion(q[k])).T @ axis
        observations.append(AxisObservation(EPOCH + TimeDelta(d * u.day), axis, direction, 0.5 * u.deg))
    rate = np.linalg.norm(true_spin(2.0))
    observations.append(SpinRateObservation(EPOCH + TimeDelta(2.0 * u.day), (rate + rng.normal(0, 0.01)) * u.rad / u.day,
                                            0.01 * u.rad / u.day))
    rotation, precession = TRUTH.periods
    observations.append(PeriodObservation(EPOCH, "precession", precession + rng.normal(0, 0.05) * u.day, 0.05 * u.day))
    observations.append(PeriodObservation(EPOCH, "rotation", rotation + rng.normal(0, 0.05) * u.day, 0.05 * u.day))
    return observations


@pytest.mark.parametrize("backend", ["exact", "dop853", "taylor"])
def test_the_analytic_jacobian_matches_central_differences_of_the_residuals(backend):
    # Every observation kind, both sides of the epoch, at a point off the truth (δθ ≠ 0 exercises
    # J_r). Reference: central differences with h = 1e-6 (relative to each parameter's scale), whose
    # error is ~h² |r'''| + ε|r|/h ≈ 1e-8 here; tolerance 1e-6 relative to the largest entry.
    rng = np.random.default_rng(3)
    observations = mixed_observations(rng)
    days = np.array([(obs.epoch.tdb - EPOCH.tdb).to_value(u.day) for obs in observations])
    sources = (PERTURBER,) if backend in ("dop853", "taylor") else ()
    problem = ResidualModel(observations, days, CORE[:4], MOMENTS[2], P, True, TRUE_Z[6:], backend, sources, 1e-13)
    z = TRUE_Z + np.array([0.02, -0.01, 0.03, 0.01, -0.01, 0.02, 0.01, -0.005])
    _, jacobian = problem.evaluate(z)
    numeric = np.empty_like(jacobian)
    for j in range(z.size):
        h = 1e-6 * max(abs(z[j]), 1.0)
        step = np.zeros(z.size)
        step[j] = h
        numeric[:, j] = (problem.evaluate(z + step)[0] - problem.evaluate(z - step)[0]) / (2 * h)
    np.testing.assert_allclose(jacobian, numeric, rtol=0, atol=1e-6 * np.abs(jacobian).max())


def quat_conjugate4(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def _attitude_error(q_fit):
    """Fitted δθ (= 0) minus the truth's, with q_true = q_fit ⊗ exp(δθ_true/2)."""
    q = quat_multiply(quat_conjugate4(q_fit), CORE[:4])
    q = q if q[0] >= 0 else -q
    s = np.linalg.norm(q[1:])
    return -(2.0 * np.arctan2(s, q[0]) * q[1:] / s if s > 0 else np.zeros(3))


def _mahalanobis(result, truth):
    """(z − truth)ᵀ C⁻¹ (z − truth), the attitude error taken about the fitted attitude."""
    n = result.values.size
    error = np.concatenate([_attitude_error(result.state.core_state()[:4]), result.values[3:] - truth[3:n]])
    return float(error @ np.linalg.solve(result.covariance, error)), error


def test_a_torque_free_fit_recovers_the_toutatis_state_and_moment_ratios():
    rng = np.random.default_rng(11)
    observations = attitude_observations(np.linspace(0.0, 30.0, 25), rng)
    result = fit_rotation(observations, first_guess(), EPOCH)
    assert result.converged and result.backend == "exact"
    d2, error = _mahalanobis(result, TRUE_Z)
    # χ²(8) has a 99.9 % quantile of 26.1: a correct fit and covariance exceed it once in 1000 seeds.
    assert d2 < 26.1, (d2, error)
    assert abs(result.chi2 - result.dof) < 5 * np.sqrt(2 * result.dof)
    assert np.all(result.standard_errors[6:] < 0.05)  # the ratios are determined, not just bounded
    assert result.state.body.principal_moments[2] == first_guess().body.principal_moments[2]  # C is kept
    assert "A/C" in result.report()


def test_a_torqued_fit_needs_the_torque_and_recovers_the_truth_with_it():
    rng = np.random.default_rng(5)
    observations = attitude_observations(np.linspace(0.0, 30.0, 25), rng, torqued=True)
    result = fit_rotation(observations, first_guess(), EPOCH, sources=[PERTURBER])
    assert result.backend == "dop853"
    d2, error = _mahalanobis(result, TRUE_Z)
    assert d2 < 26.1, (d2, error)
    assert abs(result.chi2 - result.dof) < 5 * np.sqrt(2 * result.dof)
    # the same data fitted without the torque: the model cannot follow them (χ² far above its dof)
    free = fit_rotation(observations, first_guess(), EPOCH, max_nfev=200)
    assert free.chi2 > free.dof + 10 * np.sqrt(2 * free.dof)  # 10σ of χ²(dof): rejected


def _coverage(draws, seed):
    # 25 attitudes over 30 days (~3 per 3.4-d rotation): with 12 the sampling aliases the spin and some
    # draws end on a second, spurious minimum at the edge of the physical region (refused as not
    # converged). σ = 0.4° puts the truth's B/C = 0.953 five of its σ (0.009) from the edge B/C = 1, so
    # the edge does not truncate the distribution being checked (at 1°, 1 draw in ~100 hit it).
    rng = np.random.default_rng(seed)
    days = np.linspace(0.0, 30.0, 25)
    inside, d2s = 0, []
    for _ in range(draws):
        result = fit_rotation(attitude_observations(days, rng, sigma=0.4 * u.deg), first_guess(), EPOCH)
        d2, _ = _mahalanobis(result, TRUE_Z)
        d2s.append(d2)
        inside += d2 < 13.36  # the 90 % quantile of χ²(8)
    return inside / draws, np.mean(d2s)


def test_the_covariance_covers_the_truth_over_noise_draws():
    # 40 draws: the fraction inside the 90 % ellipsoid has a binomial σ of 0.047, the mean Mahalanobis
    # d² (expected 8 for χ²(8)) a σ of √(16/40) = 0.63; bounds at about 3σ.
    fraction, mean_d2 = _coverage(40, 2026)
    assert 0.75 <= fraction <= 1.0, fraction
    assert abs(mean_d2 - 8.0) < 2.0, mean_d2


@pytest.mark.slow
def test_the_covariance_covers_the_truth_over_many_noise_draws():
    # 1000 draws: binomial σ 0.0095 on the 90 % fraction, σ 0.13 on the mean d²; bounds at about 3σ.
    fraction, mean_d2 = _coverage(1000, 7)
    assert abs(fraction - 0.9) < 0.03, fraction
    assert abs(mean_d2 - 8.0) < 0.4, mean_d2


def test_multi_start_finds_the_phase_a_single_start_misses():
    # A first guess turned by 180° about the angular momentum: the spin is right, the phase is not. From
    # it a single start ends in a local minimum (measured χ² ≈ 1.2e5 for 39 dof with this seed, and for
    # 4 of 6 seeds tried); four starts over the phase include the truth's basin.
    rng = np.random.default_rng(0)
    observations = attitude_observations(np.linspace(0.0, 20.0, 15), rng)
    momentum = quat_to_attitude(CORE[:4]).T @ (MOMENTS * CORE[4:])
    turned = quat_multiply(rotation_quaternion(np.pi * momentum / np.linalg.norm(momentum)), CORE[:4])
    guess = RotationState.from_matrix(BODY, P.T @ quat_to_attitude(turned), TRUTH.angular_velocity)
    single = fit_rotation(observations, guess, EPOCH, fit_moments=False)
    assert single.chi2 > 100 * single.dof  # converged, but to the wrong phase
    result = fit_rotation(observations, guess, EPOCH, multi_start=4, fit_moments=False)
    assert len(result.starts) == 4
    assert abs(result.chi2 - result.dof) < 5 * np.sqrt(2 * result.dof)
    assert result.chi2 == min(2 * cost for _, cost, status in result.starts if status > 0)


def axis_observations(days, axis, rng, sigma_deg=1.0):
    """Noisy inertial directions of one body axis (user axes) of the torque-free truth."""
    q = true_attitudes(days)
    out = []
    for k, d in enumerate(days):
        direction = quat_to_attitude(user_quaternion(q[k])).T @ axis + rng.normal(0, np.deg2rad(sigma_deg), 3)
        out.append(AxisObservation(EPOCH + TimeDelta(d * u.day), axis, direction, sigma_deg * u.deg))
    return out


def test_a_fit_reports_parameters_the_data_do_not_separate():
    # Eight attitudes within one day, 20 days after the epoch: the spin at the epoch is an extrapolation
    # and ωx, ωy trade off (measured correlation −0.989 for seeds 0 and 1, −0.992 for seed 2).
    rng = np.random.default_rng(0)
    observations = attitude_observations(np.linspace(20.0, 21.0, 8), rng)
    guess = first_guess(rotation_deg=(1.0, 1.0, 1.0), spin_factor=1.0, moments=(3.0836, 3.235, 1.0))
    with pytest.warns(UnseparatedParametersWarning, match="ωx and ωy"):
        result = fit_rotation(observations, guess, EPOCH, fit_moments=False, correlation_threshold=0.98)
    assert [(a, b) for a, b, _ in result.unseparated] == [("ωx", "ωy")]
    assert result.unseparated[0][2] < -0.98
    assert "do not separate" in result.report()
    # the same data with the default threshold (0.99) raise no warning: the threshold is the one named
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnseparatedParametersWarning)
        assert fit_rotation(observations, guess, EPOCH, fit_moments=False).unseparated == ()


def test_data_that_cannot_determine_a_combination_raise_singular_geometry():
    # Attitudes at the epoch fix δθ only; the spin and the two ratios (5 parameters) meet just three
    # numbers, a spin rate and two periods: the Jacobian has rank 6 of 8, refused at the first guess.
    rng = np.random.default_rng(0)
    rotation, precession = TRUTH.periods
    observations = attitude_observations(np.zeros(3), rng) + [
        SpinRateObservation(EPOCH, 105.0 * u.deg / u.day, 1.0 * u.deg / u.day),
        PeriodObservation(EPOCH, "rotation", rotation, 0.05 * u.day),
        PeriodObservation(EPOCH, "precession", precession, 0.05 * u.day)]
    with pytest.raises(SingularGeometryError, match="at the first guess: .*condition number .* cannot separate"):
        fit_rotation(observations, first_guess(), EPOCH)
    # attitudes at the epoch only: nothing depends on the spin at all
    with pytest.raises(SingularGeometryError, match="at the first guess: .*do not depend on ωx, ωy, ωz, A/C, B/C at all"):
        fit_rotation(attitude_observations(np.zeros(3), rng), first_guess(), EPOCH)


def test_the_plot_shows_every_observation_kind():
    rng = np.random.default_rng(2)
    result = fit_rotation(mixed_observations(rng), first_guess(), EPOCH)
    ax = result.plot()
    assert {line.get_label() for line in ax.get_lines()} >= {"Attitude", "Axis", "SpinRate", "Period"}
    matplotlib.pyplot.close("all")


def test_bad_input_gets_specific_errors():
    rng = np.random.default_rng(1)
    observations = attitude_observations(np.array([0.0, 5.0]), rng)
    with pytest.raises(TooFewObservationsError, match="6 residual components, but the fit has 8 parameters"):
        fit_rotation(observations, first_guess(), EPOCH)
    start, end = EPOCH, EPOCH + TimeDelta(3 * u.day)
    with pytest.raises(ObservationOutsideSpanError, match="outside the model span"):
        fit_rotation(observations, first_guess(), EPOCH, fit_moments=False, span=(start, end))
    # a sampled torque source that ends before the last observation
    from spinorbit.core.model.perturbers import sampled_source

    sample_days = np.linspace(-1.0, 3.0, 9)
    positions = np.column_stack([np.cos(sample_days), np.sin(sample_days), np.zeros_like(sample_days)])
    velocities = np.column_stack([-np.sin(sample_days), np.cos(sample_days), np.zeros_like(sample_days)])
    source = sampled_source(1e-3, sample_days, positions, velocities)
    with pytest.raises(ObservationOutsideSpanError, match="sampled torque sources"):
        fit_rotation(observations, first_guess(), EPOCH, fit_moments=False, sources=[source])
    # one body axis seen at one epoch, four times: the rotation about it and the spin are free
    axis_obs = [AxisObservation(EPOCH, [0, 0, 1], [0.2, 0.3, 0.9], 1 * u.deg) for _ in range(4)]
    with pytest.raises(SingularGeometryError, match="condition number|do not depend"):
        fit_rotation(axis_obs, first_guess(), EPOCH, fit_moments=False)
    with pytest.raises(FitNotConvergedError, match="no start of 1 converged") as caught:
        fit_rotation(attitude_observations(np.linspace(0, 30, 10), rng), first_guess(), EPOCH, max_nfev=1)
    assert caught.value.result is not None and caught.value.result.status == 0
    with pytest.raises(InvalidObservationError, match="positive"):
        AttitudeObservation(EPOCH, [1, 0, 0, 0], -1 * u.deg)
    with pytest.raises(InvalidObservationError, match="astropy Time"):
        SpinRateObservation("1992-11-09", 1 * u.deg / u.day, 0.1 * u.deg / u.day)
    with pytest.raises(InvalidObservationError, match="unit quaternion"):
        AttitudeObservation(EPOCH, [1, 1, 0, 0], 1 * u.deg)
    with pytest.raises(InvalidObservationError, match="kind"):
        PeriodObservation(EPOCH, "spin", 5 * u.day, 0.1 * u.day)


def test_no_warning_for_a_well_determined_fit():
    rng = np.random.default_rng(12)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnseparatedParametersWarning)
        fit_rotation(attitude_observations(np.linspace(0.0, 30.0, 20), rng), first_guess(), EPOCH)
