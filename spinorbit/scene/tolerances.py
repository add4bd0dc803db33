"""The one rule turning a scene's error share into each integrator's tolerance, and the a posteriori check.

A scene's tolerance is an attitude angle (rad). What the plan leaves out (dropped perturbers,
back-reaction) may use up to :data:`DROP_SHARE` of it and is paid first; the rest, the *integration
share*, is split between the integration and the sampling of the perturbers:

- the **integration** gets a first local tolerance from the share (:func:`first_tolerance`: the
  DOP853 rtol, the Taylor tol, REBOUND's BS eps), chosen so that the global error lands at about
  0.3 × the share; the run is then checked against a second run at :data:`CHECK_RTOL_FACTOR` × that
  tolerance, and repeated at 1/:data:`RETRY_FACTOR` of it while the difference is above
  :data:`ACCEPTED_SHARE` × the share (:func:`refine`);
- the **sampling** at the scene's ``sample_tolerance`` ε (a relative position error) makes a relative
  torque error of at most 3ε, bounded like a dropped torque (:func:`sampling_error_bound`); the
  planner's survey samples at the looser :data:`SURVEY_TOLERANCE` unless it is kept for the run
  (:func:`survey_tolerance`).

Every user of a tolerance (the planner, the route runners, ``benchmarks/bench_scene_skips.py``)
calls these functions; ``docs/scenes.md`` explains the numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "ACCEPTED_SHARE",
    "CHECK_RTOL_FACTOR",
    "COUPLED_EPS_RANGE",
    "DROP_SHARE",
    "MAX_RTOL_RETRIES",
    "RETRY_FACTOR",
    "RTOL_PER_ERROR",
    "RTOL_RANGE",
    "SAMPLING_TORQUE_FACTOR",
    "SURVEY_TOLERANCE",
    "TAYLOR_TOL_PER_ERROR",
    "ToleranceRule",
    "check_tolerance",
    "first_tolerance",
    "initial_rtol",
    "refine",
    "sampling_error_bound",
    "survey_tolerance",
]

#: Share of the tolerance that what the plan leaves out (dropped perturbers, back-reaction) may use.
DROP_SHARE = 0.5
#: DOP853's global error is ≈ 300 × rtol in work-precision scene (a) (docs/performance.md): the first
#: rtol is the share / 1000, global error ≈ 0.3 × the share.
RTOL_PER_ERROR = 1e-3
#: The Taylor method's global error is 2–60 × tol there: share × 0.3 / 60 puts it at ≤ 0.3 × the share too.
TAYLOR_TOL_PER_ERROR = 0.3 / 60.0
#: Range of the DOP853 rtol and the Taylor tol (below 1e-13 double precision gains nothing).
RTOL_RANGE = (1e-13, 1e-6)
#: BS eps range of the coupled route. Its error control covers the orbits too (positions ~1 au):
#: looser than 1e-10 would put the orbits' error above the one-way sampler's default 1e-10.
COUPLED_EPS_RANGE = (1e-13, 1e-10)
#: Factor between the run's tolerance and the check run's (error estimate = their difference); for the
#: Taylor tol and the BS eps too (the name is the one scripts know).
CHECK_RTOL_FACTOR = 10.0
#: Tighter tolerance of a retry: the tolerance / RETRY_FACTOR.
RETRY_FACTOR = 100.0
#: Retries of the integration when the a posteriori estimate misses its share.
MAX_RTOL_RETRIES = 2
#: The integration's part of the integration share (the sampling takes the rest).
ACCEPTED_SHARE = 0.5
#: Relative position tolerance of the planner's survey of the perturber distances.
SURVEY_TOLERANCE = 1e-6
#: A relative position error ε of a sampled perturber changes its degree-2 torque by at most 3ε (1/r³).
SAMPLING_TORQUE_FACTOR = 3.0


@dataclass(frozen=True)
class ToleranceRule:
    """How one integrator's tolerance follows from an error share (rad).

    Attributes
    ----------
    knob : str
        The tolerance's name in the plan ("rtol", "tol", "eps").
    per_error : float
        First tolerance per radian of integration share.
    lowest, highest : float
        Range of the first tolerance; ``lowest`` is also the floor of the retries.
    check_ceiling : float
        Loosest tolerance of the check run.
    """

    knob: str
    per_error: float
    lowest: float
    highest: float
    check_ceiling: float


_DOP853 = ToleranceRule("rtol", RTOL_PER_ERROR, *RTOL_RANGE, check_ceiling=1e-4)
RULES = {
    "quaternion": _DOP853,
    "elements": _DOP853,
    "taylor": ToleranceRule("tol", TAYLOR_TOL_PER_ERROR, *RTOL_RANGE, check_ceiling=1e-4),
    "rebound-bs": ToleranceRule("eps", RTOL_PER_ERROR, *COUPLED_EPS_RANGE, check_ceiling=1e-6),
}


def _rule(integrator):
    try:
        return RULES[integrator]
    except KeyError:
        raise ValueError(f"integrator: expected one of {tuple(RULES)}; got {integrator!r}") from None


def first_tolerance(integrator, share_rad):
    """First local tolerance of ``integrator`` for an integration error share (rad).

    Parameters
    ----------
    integrator : {"quaternion", "elements", "taylor", "rebound-bs"}
        The DOP853 integrators take an rtol, the Taylor method a tol, REBOUND's BS an eps.
    share_rad : float
        The integration share of the tolerance, rad.

    Returns
    -------
    float
        ``share_rad`` × the rule's tolerance per error, clipped to its range.
    """
    rule = _rule(integrator)
    return float(np.clip(share_rad * rule.per_error, rule.lowest, rule.highest))


def initial_rtol(error_share_rad):
    """First DOP853 rtol for an integration error share (rad), clipped to :data:`RTOL_RANGE`."""
    return first_tolerance("quaternion", error_share_rad)


def check_tolerance(integrator, tolerance):
    """The check run's tolerance: :data:`CHECK_RTOL_FACTOR` × the run's, at most the rule's ceiling."""
    return min(tolerance * CHECK_RTOL_FACTOR, _rule(integrator).check_ceiling)


def refine(integrator, first, share_rad, run_and_check, attempted=None):
    """Run at ``first``, then 1/:data:`RETRY_FACTOR` tighter while the a posteriori error misses its share.

    Parameters
    ----------
    integrator : str
        As in :func:`first_tolerance`.
    first : float
        The first tolerance (the plan's).
    share_rad : float
        The integration share (rad); the run is accepted when its error is at most
        :data:`ACCEPTED_SHARE` × the share, or its tolerance has reached the rule's floor.
    run_and_check : callable
        ``run_and_check(tolerance, check_tolerance) -> (result, error_rad)``: the run and its
        difference to the check run.
    attempted : callable, optional
        Called with the attempt's index (0 … :data:`MAX_RTOL_RETRIES`) after each attempt (progress).

    Returns
    -------
    result, error_rad, tolerance
        Those of the last attempt.
    """
    rule = _rule(integrator)
    tolerance = first
    for attempt in range(MAX_RTOL_RETRIES + 1):
        result, error = run_and_check(tolerance, check_tolerance(integrator, tolerance))
        if attempted is not None:
            attempted(attempt)
        if error <= ACCEPTED_SHARE * share_rad or tolerance <= rule.lowest:
            break
        tolerance = max(tolerance / RETRY_FACTOR, rule.lowest)
    return result, error, tolerance


def sampling_error_bound(sample_tolerance, kept_worst_attitude_rad):
    """The attitude error (rad) of sampling the kept perturbers at a relative position error ``sample_tolerance``.

    The torque error (relative size :data:`SAMPLING_TORQUE_FACTOR` × ε) points in no particular
    direction, so it does not share the torque's cancellation: it is bounded with the kept
    perturbers' summed worst-attitude bound (rad).
    """
    return SAMPLING_TORQUE_FACTOR * sample_tolerance * kept_worst_attitude_rad


def survey_tolerance(kept_for_the_run, sample_tolerance):
    """The planner survey's sampling tolerance: the run's ``sample_tolerance`` when the survey is kept for it."""
    return sample_tolerance if kept_for_the_run else SURVEY_TOLERANCE
