"""Least-squares fit of a rotation state (and the moment ratios) to observations, with the analytic Jacobian.

The parameters are z = (δθ, ω₀, A/C, B/C): the attitude at the epoch as q₀ = q_ref ⊗ exp(δθ/2) about the
first guess's q_ref, the body angular velocity on the principal axes (rad/day), and, when
``fit_moments``, the moment ratios at fixed C (``docs/conventions.md``, "State transition matrices").
The whitened residuals of every observation (:mod:`spinorbit.fit.observations`) and their Jacobian

    ∂r/∂z = ∂r/∂x(t) · [Φ(t) · diag(J_r(δθ), 1),  Ψ(t)] + ∂r/∂p|_direct

come from one propagation with its STM (:mod:`spinorbit.fit.propagation`: the exact free flow, or
DOP853 with its variational equations when torques act), and go to ``scipy.optimize.least_squares``
(trust-region reflective, ``x_scale="jac"``). At the solution the attitude is re-centred (δθ = 0) and
the formal covariance is (JᵀJ)⁻¹.

Identifiability is judged on the column-normalised Jacobian: a condition number above
``condition_threshold`` (default 1e10) means no covariance exists (:class:`SingularGeometryError`,
at the first guess already or at the solution); a pair of parameters with |correlation| above
``correlation_threshold`` (default 0.99) is reported in ``FitResult.unseparated`` with an
:class:`UnseparatedParametersWarning`.

Multi-start over the unknown phase: ``multi_start`` = n runs from the first guess turned about its
inertial angular momentum by 2πk/n (the phase that periods and spin rates leave free); the converged
run of lowest cost is returned and every run is listed in ``FitResult.starts``.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from astropy import units as u
from astropy.time import Time
from scipy.optimize import least_squares

from spinorbit.body import TRIANGLE_SLACK, RigidBody
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.dynamics.validation import validate_sampled_span
from spinorbit.core.errors import SingularElementsError
from spinorbit.core.integrators.dop853 import IntegrationError
from spinorbit.core.math.rotations import quat_multiply, quat_to_attitude
from spinorbit.fit.errors import (
    FitError,
    FitNotConvergedError,
    InvalidObservationError,
    ObservationOutsideSpanError,
    SingularGeometryError,
    TooFewObservationsError,
    UnseparatedParametersWarning,
)
from spinorbit.fit.observations import OBSERVATION_TYPES, right_jacobian, rotation_quaternion
from spinorbit.fit.propagation import BACKENDS, propagate_with_stm
from spinorbit.fit.result import FitResult
from spinorbit.state import RotationState

STATE_NAMES = ("δθx", "δθy", "δθz", "ωx", "ωy", "ωz")
RATIO_NAMES = ("A/C", "B/C")
#: least_squares stopping tolerances: far below the noise of any real observation set.
TOLERANCE = 1e-10
#: A Jacobian column below this fraction of the largest is rounding, not information (Φ(0) = 1 to ~1e-16).
BLIND_COLUMN = 1e-12
#: Largest χ² decrease a further Gauss–Newton step may promise at a converged solution.
CONVERGENCE_DECREASE = 1e-2


def _days_since(epoch, times):
    return np.array([(t.tdb - epoch.tdb).to_value(u.day) for t in times])


def _check_inputs(observations, first_guess, epoch, span, sources, backend, fit_moments):
    if not isinstance(first_guess, RotationState):
        raise TypeError(f"first_guess: expected a spinorbit.RotationState, got {type(first_guess).__name__}.")
    if not isinstance(epoch, Time) or not epoch.isscalar:
        raise FitError(f"epoch: expected one astropy Time (the epoch of first_guess), got {epoch!r}.")
    observations = tuple(observations)
    if not observations:
        raise TooFewObservationsError("observations: expected at least one observation, got none.")
    for k, obs in enumerate(observations):
        if not isinstance(obs, OBSERVATION_TYPES):
            raise InvalidObservationError(f"observations[{k}]: expected one of "
                                          f"{[t.__name__ for t in OBSERVATION_TYPES]}, got {type(obs).__name__}.")
    n_params = len(STATE_NAMES) + (len(RATIO_NAMES) if fit_moments else 0)
    n_residuals = sum(obs.size for obs in observations)
    if n_residuals < n_params:
        raise TooFewObservationsError(
            f"{len(observations)} observations give {n_residuals} residual components, but the fit has {n_params} "
            f"parameters ({', '.join(STATE_NAMES + (RATIO_NAMES if fit_moments else ()))}); an attitude gives 3, an "
            "axis direction 2, a spin rate or a period 1. Add observations, or keep the moments fixed "
            "(fit_moments=False).")
    times = _days_since(epoch, [obs.epoch for obs in observations])
    if span is not None:
        start, end = span
        lo, hi = (start.tdb - epoch.tdb).to_value(u.day), (end.tdb - epoch.tdb).to_value(u.day)
        outside = np.flatnonzero((times < lo) | (times > hi))
        if outside.size:
            k = int(outside[0])
            raise ObservationOutsideSpanError(
                f"observations[{k}] at {observations[k].epoch.isot} lies outside the model span "
                f"[{start.isot}, {end.isot}] ({outside.size} of {len(observations)} do); drop them or widen the span.")
    if backend == "auto":
        backend = "dop853" if sources else "exact"
    if backend not in BACKENDS:
        raise FitError(f"backend: expected 'auto' or one of {BACKENDS}, got {backend!r}.")
    if backend == "exact" and sources:
        raise FitError("backend 'exact' is the torque-free flow, but torque sources were given; use backend='dop853' "
                       "(or 'auto').")
    if sources:
        model = make_model(np.asarray(first_guess.body.principal_moments), list(sources))
        for side in (times[times > 0.0], times[times < 0.0]):
            if side.size:
                try:
                    validate_sampled_span(model, 0.0, np.sort(side))
                except ValueError as error:
                    raise ObservationOutsideSpanError(
                        f"an observation lies outside the span of the sampled torque sources (days since the epoch): "
                        f"{error}") from None
    return observations, times, backend


class ResidualModel:
    """Residuals and Jacobian of one fit about one reference attitude (cached per parameter vector)."""

    def __init__(self, observations, times, q_ref, big_c, to_principal, fit_moments, ratios0, backend, sources, rtol,
                 physical=True):
        self.observations, self.times, self.q_ref = observations, times, q_ref
        self.big_c, self.to_principal, self.fit_moments = big_c, to_principal, fit_moments
        self.ratios0, self.backend, self.sources, self.rtol = ratios0, backend, sources, rtol
        self.physical = physical
        self._cached = None

    def moments(self, z):
        ratios = z[6:8] if self.fit_moments else self.ratios0
        if not (0.0 < ratios[0] < ratios[1] < 1.0):
            raise FitError(f"the moment ratios left the ordered region 0 < A/C < B/C < 1 (A/C = {ratios[0]!r}, "
                           f"B/C = {ratios[1]!r}); start nearer the truth, or fix the moments (fit_moments=False).")
        if self.physical and ratios[0] + ratios[1] < 1.0 - TRIANGLE_SLACK:
            raise FitError(f"the moment ratios left the physical region A/C + B/C ≥ 1 (got {ratios[0]!r} + {ratios[1]!r}); "
                           "no mass distribution has them. Start nearer the truth or fix the moments.")
        return np.array([ratios[0] * self.big_c, ratios[1] * self.big_c, self.big_c])

    def attitude(self, z):
        return quat_multiply(self.q_ref, rotation_quaternion(z[:3]))

    def residuals_or_rejection(self, z):
        """The residuals, or +inf where the model is undefined (moment ratios out of order, J = 0 for the exact
        STM): least_squares' trust-region step then shrinks (scipy's trf treats a non-finite trial
        residual as a rejected step), and the Jacobian is only ever asked at accepted, valid points."""
        try:
            return self.evaluate(z)[0]
        except FitError:
            return np.full(self.size, np.inf)

    @property
    def size(self):
        return sum(obs.size for obs in self.observations)

    def evaluate(self, z):
        if self._cached is not None and np.array_equal(self._cached[0], z):
            return self._cached[1], self._cached[2]
        moments = self.moments(z)
        try:
            q, w, phi, psi = propagate_with_stm(self.backend, self.attitude(z), z[3:6], moments, self.times,
                                                self.sources, self.rtol)
        except SingularElementsError as error:
            raise FitError(f"the exact STM is undefined at this iterate ({error}); use backend='dop853'.") from None
        except IntegrationError as error:
            raise FitError(f"the {self.backend} propagation with its STM stopped at this iterate ({error}).") from None
        rows, jac = [], []
        attitude_chain = right_jacobian(z[:3])
        for k, obs in enumerate(self.observations):
            r, d_state, d_direct = obs.residuals(q[k], w[k], moments, self.to_principal)
            d_initial = d_state @ phi[k]
            block = np.hstack([d_initial[:, :3] @ attitude_chain, d_initial[:, 3:]])
            if self.fit_moments:
                block = np.hstack([block, d_state @ psi[k] + d_direct])
            rows.append(r)
            jac.append(block)
        residuals, jacobian = np.concatenate(rows), np.vstack(jac)
        if not (np.all(np.isfinite(residuals)) and np.all(np.isfinite(jacobian))):
            raise FitError("the residuals or their Jacobian are not finite at this iterate; check the observations' "
                           "units and the first guess.")
        self._cached = (z.copy(), residuals, jacobian)
        return residuals, jacobian


def _conditioning(jacobian, names, threshold, where):
    """(condition number, covariance) of a whitened Jacobian, or SingularGeometryError above ``threshold``."""
    norms = np.linalg.norm(jacobian, axis=0)
    blind_columns = norms <= BLIND_COLUMN * norms.max()
    if np.any(blind_columns):
        blind = [names[i] for i in np.flatnonzero(blind_columns)]
        raise SingularGeometryError(f"{where}: the observations do not depend on {', '.join(blind)} at all; add "
                                    "observations that constrain them, or fix them.")
    _, s, vt = np.linalg.svd(jacobian / norms, full_matrices=False)
    condition = float(s[0] / s[-1])
    if not condition <= threshold:
        weakest = vt[-1]
        involved = [f"{names[i]} ({weakest[i]:+.2f})" for i in np.argsort(-np.abs(weakest))[:3]]
        raise SingularGeometryError(
            f"{where}: the normalised Jacobian has condition number {condition:.3g} > {threshold:g}, so the data "
            f"cannot separate the combination {' + '.join(involved)}; add observations at other epochs or of other "
            "kinds, or fix some parameters (fit_moments=False).")
    scaled = (vt.T / s**2) @ vt
    return condition, scaled / np.outer(norms, norms)


def _fitted_body(body, ratios, big_c):
    principal = np.array([ratios[0] * big_c, ratios[1] * big_c, big_c])
    user = np.empty(3)
    permutation = np.argmax(np.abs(body.to_principal), axis=1)  # principal axis i is user axis permutation[i]
    user[permutation] = principal
    return RigidBody(user * body.moment_unit if body.moment_unit != u.dimensionless_unscaled else user,
                     mass=body.mass, radius=body.radius, name=body.name, physical=body.physical)


def _phase_turned(q_ref, omega, moments, phase):
    """The first guess turned by ``phase`` about its inertial angular momentum (a left rotation)."""
    momentum = quat_to_attitude(q_ref).T @ (moments * omega)
    axis = momentum / np.linalg.norm(momentum)
    return quat_multiply(rotation_quaternion(phase * axis), q_ref)


def fit_rotation(observations, first_guess, epoch, *, fit_moments=True, sources=(), span=None, backend="auto",
                 multi_start=1, rtol=1e-11, max_nfev=100, correlation_threshold=0.99, condition_threshold=1e10):
    """Fit a rotation state (and the moment ratios A/C, B/C) to observations by least squares.

    Parameters
    ----------
    observations : sequence
        :class:`AttitudeObservation`, :class:`AxisObservation`, :class:`SpinRateObservation`,
        :class:`PeriodObservation` (any mix, any order, on both sides of the epoch).
    first_guess : RotationState
        The starting state at ``epoch``; its body gives C and the starting ratios.
    epoch : Time
        Epoch of ``first_guess`` and of the fitted state.
    fit_moments : bool
        Fit (A/C, B/C) as well (True) or keep the body's.
    sources : sequence
        Torque sources of :mod:`spinorbit.core.model.perturbers` (times in TDB days since ``epoch``,
        lengths and μ in the units of the moments' time unit, day), for a torqued fit.
    span : (Time, Time), optional
        The span on which the model holds; observations outside it are refused.
    backend : {"auto", "exact", "dop853", "taylor"}
        "auto": the exact free-flow STM without sources, DOP853 variational equations with them.
        "taylor": the Taylor integrator's variational recurrences (with or without sources).
    multi_start : int
        Number of starts over the phase about the angular momentum (module docstring).
    rtol : float
        DOP853 (or Taylor) tolerance of the propagation and its STM.
    max_nfev : int
        Cap on least_squares' function evaluations per start.
    correlation_threshold, condition_threshold : float
        Identifiability thresholds (module docstring).

    Returns
    -------
    FitResult

    Raises
    ------
    TooFewObservationsError, ObservationOutsideSpanError, SingularGeometryError, InvalidObservationError
        Bad input (the message says what was expected and what to do).
    FitNotConvergedError
        No start met a convergence test within ``max_nfev``; ``error.result`` is the best least_squares
        result.
    """
    if not (isinstance(multi_start, int) and multi_start >= 1):
        raise FitError(f"multi_start: expected an integer ≥ 1, got {multi_start!r}.")
    observations, times, backend = _check_inputs(observations, first_guess, epoch, span, sources, backend,
                                                 fit_moments)
    body = first_guess.body
    big_a, big_b, big_c = body.principal_moments
    ratios0 = np.array([big_a / big_c, big_b / big_c])
    core = first_guess.core_state()
    q_guess, omega_guess = core[:4], core[4:]
    names = STATE_NAMES + (RATIO_NAMES if fit_moments else ())
    z0 = np.concatenate([np.zeros(3), omega_guess] + ([ratios0] if fit_moments else []))

    def problem_at(q_ref):
        return ResidualModel(observations, times, q_ref, big_c, body.to_principal, fit_moments, ratios0, backend,
                             tuple(sources), rtol, body.physical)

    _conditioning(problem_at(q_guess).evaluate(z0)[1], names, condition_threshold, "at the first guess")
    runs = []
    for k in range(multi_start):
        phase = 2.0 * math.pi * k / multi_start
        problem = problem_at(_phase_turned(q_guess, omega_guess, np.array([big_a, big_b, big_c]), phase))
        solution = least_squares(problem.residuals_or_rejection, z0, jac=lambda z: problem.evaluate(z)[1],
                                 method="trf", x_scale="jac", xtol=TOLERANCE, ftol=TOLERANCE, gtol=TOLERANCE,
                                 max_nfev=max_nfev)
        runs.append((phase, problem, solution))
    # A run counts as converged only if least_squares met a test AND one more Gauss–Newton step about
    # the solution would lower χ² by less than CONVERGENCE_DECREASE: a run stopped against the edge of
    # the valid region (moment ratios at A/C + B/C = 1 or B/C = 1) passes scipy's ftol but not this.
    converged, failures = [], []
    for phase, problem, solution in runs:
        if solution.status <= 0:
            failures.append(f"start at phase {phase:.3f} rad: {solution.message}")
            continue
        q_fit = problem.attitude(solution.x)
        z_fit = np.concatenate([np.zeros(3), solution.x[3:]])
        residuals, jacobian = problem_at(q_fit).evaluate(z_fit)
        condition, covariance = _conditioning(jacobian, names, condition_threshold, "at the solution")
        gradient = jacobian.T @ residuals
        decrease = float(gradient @ covariance @ gradient)
        if decrease > CONVERGENCE_DECREASE:
            failures.append(f"start at phase {phase:.3f} rad stopped where a Gauss–Newton step would still lower χ² "
                            f"by {decrease:.3g} (at A/C, B/C = {problem.moments(z_fit)[:2] / big_c}: the edge of the "
                            "valid region?)")
            continue
        converged.append((solution.cost, phase, solution, q_fit, z_fit, residuals, condition, covariance))
    if not converged:
        best = min(runs, key=lambda run: run[2].cost)[2]
        raise FitNotConvergedError(
            f"no start of {multi_start} converged within max_nfev = {max_nfev}: " + "; ".join(failures)
            + ". Raise max_nfev, improve the first guess, add observations (sparse sampling aliases the "
            "spin) or use multi_start.", best)
    _, phase, solution, q_fit, z_fit, residuals, condition, covariance = min(converged, key=lambda run: run[0])
    sigma = np.sqrt(np.diag(covariance))
    correlation = covariance / np.outer(sigma, sigma)
    unseparated = tuple((names[i], names[j], float(correlation[i, j])) for i in range(len(names))
                        for j in range(i + 1, len(names)) if abs(correlation[i, j]) > correlation_threshold)
    if unseparated:
        warnings.warn("the data hardly separate " + "; ".join(f"{a} and {b} (correlation {c:+.4f})"
                                                             for a, b, c in unseparated)
                      + f" (|correlation| > {correlation_threshold}); see FitResult.unseparated.",
                      UnseparatedParametersWarning, stacklevel=2)
    ratios = z_fit[6:8] if fit_moments else ratios0
    fitted_body = _fitted_body(body, ratios, big_c)
    p = body.to_principal
    state = RotationState.from_matrix(fitted_body, p.T @ quat_to_attitude(q_fit), p.T @ z_fit[3:6] * u.rad / u.day)
    kinds = tuple(type(obs).__name__.removesuffix("Observation") for obs in observations for _ in range(obs.size))
    return FitResult(
        state=state, body=fitted_body, epoch=epoch, parameter_names=names, values=z_fit, covariance=covariance,
        residuals=residuals, residual_times=np.repeat(times, [obs.size for obs in observations]),
        residual_kinds=kinds, chi2=float(residuals @ residuals), dof=int(residuals.size - len(names)),
        condition_number=condition, correlation_threshold=correlation_threshold, unseparated=unseparated,
        converged=True, backend=backend, nfev=int(solution.nfev), message=str(solution.message),
        starts=tuple((float(ph), float(sol.cost), int(sol.status)) for ph, _, sol in runs),
    )
