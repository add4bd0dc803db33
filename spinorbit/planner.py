"""The scene planner's bounds and its EXPLAIN-like plan (used by :class:`spinorbit.scene.Scene`).

The one estimate every skip rests on
------------------------------------
A torque N(s) left out of a run (a dropped perturber, or all of them for the torque-free route) changes
the body angular momentum by at most ∫|N| ds and, through it, the body angular velocity by at most
|δω(s)| ≤ (1/A) ∫₀^s |N| ds' (A the smallest principal moment). Linearising about the free motion
(Duhamel), an angular-velocity kick δω applied at time s moves the attitude at T by at most

    |δθ(T)| ≤ κ |δω| (T − s) + 2 |δL| / |L|,

the first term the accumulated phase drift, the second the tilt of the momentum (the body then
nutates about a new axis: an O(δL/L) attitude difference that does not grow). κ is the attitude
sensitivity of the free motion: 1 for a uniform rotation, larger where the periods depend steeply on
the state (near the separatrix). It is **measured**, not assumed: :func:`attitude_sensitivity`
propagates the state exactly (no integration) with ω kicked along each body axis and takes the largest
δθ/(|δω| τ) over horizons τ = T/16 … T. Summing the kicks,

    bound = SAFETY · [ κ ∫₀^T (T − s) |N(s)|/A ds + 2 ∫₀^T |N(s)| ds / |L| ],

with the degree-2 torque of a point mass μ at distance r bounded by its largest value over all
attitudes, |N| ≤ (3μ / 2r³) (C − A) (the unit vector r̂ at 45° between the A and C axes maximises
|r̂ × I r̂| = (C − A)/2). r(s) comes from a survey: the same adaptive sampler as the run
(:mod:`spinorbit.coupling.one_way`), at the loose relative tolerance :data:`SURVEY_TOLERANCE` (with a
REBOUND orbit at the run's own tolerance, and kept for the run), which still tightens its grid around
close encounters. SAFETY = 2 covers the trapezoid rule between survey
samples and the linearisation. ``tests/test_scene.py`` checks the bound against full runs: the
measured effect of a dropped torque must stay below it.

Back-reaction (one-way coupling against the fully coupled run)
--------------------------------------------------------------
A figure (C − A) of a body of mass M pulls a perturber of mass m_p at distance r with a force beyond
the point mass's, and the body back; the relative acceleration changes by at most

    |δa_q| ≤ 6 J (μ_b + μ_q) / r_q⁴ + 6 J Σ_{p≠q} μ_p / r_p⁴,      J = (C − A)/M (length²),

from the degree-2 field ∇U = (3G/2r⁴)[−tr I′ r̂ − 2 I′ r̂ + 5 (r̂·I′r̂) r̂] (MacCullagh; I′ = I − (A+C)/2 𝟙
has eigenvalues within ±(C − A)/2, so the bracket is at most 4 (C − A)); the second term is the body's
recoil from the other perturbers, which moves it relative to q too. The orbit answers an impulse δa
after a time τ with a displacement of at most :data:`ORBIT_RESPONSE` · τ · δa: for a circular orbit
(Hill's equations, any mean motion) the largest |response|/τ is 3.91, computed over 0 < nτ < 200
(the along-track drift of the changed semi-major axis); a free particle has 1. So

    |δr_q(s)| ≤ ORBIT_RESPONSE ∫₀ˢ (s − s′) |δa_q(s′)| ds′,

and the changed perturber vector changes the torque by at most 5 |N|_max(r) |δr|/r (3|δr|/r from
1/r³, 2|δr|/r from turning r̂: |δ(r̂ × I′r̂)| ≤ (C − A) |δr̂|). That torque change goes through the
same attitude bound as a dropped torque (:func:`dropped_torque_bound`); :func:`back_reaction_bound`
is their sum over the perturbers. Eccentric orbits respond more strongly near pericentre than the
circular 3.91: that is left to SAFETY (moderate e), and the bound is tested against the fully coupled
REBOUND run (``CoupledRigidBody``, ``tests/test_scene.py``).

Budget: a scene's tolerance (an attitude angle) is shared: up to :data:`DROP_SHARE` of it for the
perturbers dropped and the back-reaction left out (one-way coupling), the rest for the integrator (whose error is estimated a posteriori by a second
run at 10× the rtol) and the sampling (relative position error ε gives a relative torque error ≤ 3ε).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "ARCSEC_PER_RAD",
    "DROP_SHARE",
    "SAFETY",
    "SURVEY_TOLERANCE",
    "Decision",
    "PerturberEstimate",
    "Plan",
    "ORBIT_RESPONSE",
    "attitude_sensitivity",
    "back_reaction_bound",
    "dropped_torque_bound",
    "initial_rtol",
    "max_torque_over_a",
]

#: Factor on the linear-response bound (module docstring).
SAFETY = 2.0
#: Share of the tolerance that dropped perturbers may use; the rest goes to integration and sampling.
DROP_SHARE = 0.5
#: Relative position tolerance of the planner's survey of the perturber distances.
SURVEY_TOLERANCE = 1e-6
#: Horizons (fractions of the span) at which the attitude sensitivity κ is measured.
SENSITIVITY_HORIZONS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 1.0)
#: Attitude change (rad) the sensitivity probe aims for: large against rounding (1e-13), small
#: enough to stay linear.
SENSITIVITY_PROBE_RAD = 1e-6
#: Global DOP853 error was ≈ 300 × rtol in work-precision scene (a) (docs/performance.md); the
#: first rtol tried is the integration share / 1000, then checked a posteriori.
RTOL_PER_ERROR = 1e-3
RTOL_RANGE = (1e-13, 1e-6)
ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi
#: Largest orbit displacement per unit impulse and elapsed time (module docstring: 3.91 for a circular
#: orbit, computed from Hill's equations; rounded up).
ORBIT_RESPONSE = 4.0
#: |∇U| of a degree-2 figure ≤ FIGURE_FORCE · G (C − A) / r⁴ (module docstring).
FIGURE_FORCE = 6.0
#: |δN| ≤ TORQUE_GRADIENT · |N|_max · |δr|/r for a change δr of the perturber vector (module docstring).
TORQUE_GRADIENT = 5.0


def max_torque_over_a(moments, gm, distance):
    """Largest degree-2 torque over all attitudes divided by A: (3 μ / 2 r³) (C − A)/A, rad/day².

    Parameters
    ----------
    moments : (A, B, C)
        Principal moments, any unit (only ratios enter).
    gm : float
        Perturber's G·M, au³/day².
    distance : float or ndarray
        Distance body–perturber, au.
    """
    big_a, _, big_c = moments
    return 1.5 * gm * (big_c - big_a) / big_a / np.asarray(distance, dtype=float) ** 3


def attitude_sensitivity(state, span_days):
    """κ: the largest attitude change per unit |δω|·τ of the exact free motion (module docstring).

    Three exact propagations of ``state`` with ω kicked by δ along each body axis, compared with the
    unkicked one at the horizons τ = :data:`SENSITIVITY_HORIZONS` × ``span_days``. δ is chosen so
    that δ·span ≈ :data:`SENSITIVITY_PROBE_RAD`. Returns at least 1 (a uniform rotation's κ).
    """
    from .core.rotations import rotation_angle_between_many
    from .state import RotationState

    horizons = np.array(SENSITIVITY_HORIZONS) * span_days
    omega = state.angular_velocity.to_value("rad/day")
    kick = SENSITIVITY_PROBE_RAD / span_days
    base = np.ascontiguousarray(state.propagate_torque_free(horizons)[0])
    kappa = 1.0
    for axis in range(3):
        kicked_omega = omega.copy()
        kicked_omega[axis] += kick
        kicked = RotationState(state.body, state.quaternion, kicked_omega)
        other = np.ascontiguousarray(kicked.propagate_torque_free(horizons)[0])
        angles = rotation_angle_between_many(base, other)
        kappa = max(kappa, float(np.max(angles / (kick * horizons))))
    return kappa


def dropped_torque_bound(days, torque_over_a, span_end, kappa, momentum_over_a):
    """The attitude bound (rad) at ``span_end`` of leaving out a torque |N|/A sampled at ``days``.

    ``days`` (increasing, TDB days) and ``torque_over_a`` (rad/day²) are survey samples; the integrals
    of the module docstring are taken with the trapezoid rule. ``momentum_over_a`` is |L|/A (rad/day).
    """
    days = np.asarray(days, dtype=float)
    n = np.asarray(torque_over_a, dtype=float)
    lever = span_end - days
    drift = _trapezoid(lever * n, days)
    tilt = _trapezoid(n, days)
    return SAFETY * (kappa * drift + 2.0 * tilt / momentum_over_a)


def back_reaction_bound(days, distances, gm, gm_body, figure_per_mass, moments, span_end, kappa,
                        momentum_over_a):
    """The attitude bound (rad) at ``span_end`` of leaving the figure's force on the orbits out.

    The chain of the module docstring (*Back-reaction*): figure force → orbit displacement →
    changed torque → attitude, each step bounded, summed over the perturbers.

    Parameters
    ----------
    days : ndarray (n,)
        Survey times, TDB days (increasing).
    distances : ndarray (n, k)
        Body–perturber distances at ``days``, au.
    gm : ndarray (k,)
        Perturbers' G·M, au³/day².
    gm_body : float
        The body's G·M in the orbit model, au³/day².
    figure_per_mass : float
        J = (C − A)/M, au².
    moments : (A, B, C)
        Principal moments (only ratios enter the torque).
    span_end, kappa, momentum_over_a
        As in :func:`dropped_torque_bound`.

    Returns
    -------
    bound : float
        Attitude bound, rad.
    displacement : ndarray (k,)
        The bound on each perturber vector's displacement at ``span_end`` (au), for the plan's reason.
    """
    days = np.asarray(days, dtype=float)
    r = np.asarray(distances, dtype=float)
    gm = np.asarray(gm, dtype=float)
    pull = gm[None, :] / r**4  # μ_p / r_p⁴
    recoil = pull.sum(axis=1, keepdims=True)
    kick = FIGURE_FORCE * figure_per_mass * (gm_body / r**4 + recoil)  # |δa_q|, au/day² (μ_q term in recoil)
    # ∫₀ˢ (s − s') δa ds' = ∫₀ˢ v, v(s) = ∫₀ˢ δa: two cumulative trapezoid sums.
    displacement = ORBIT_RESPONSE * _cumulative_trapezoid(_cumulative_trapezoid(kick, days), days)
    torque = max_torque_over_a(moments, gm[None, :], r)  # |N|_max/A per perturber
    change = TORQUE_GRADIENT * torque * displacement / r
    bound = sum(dropped_torque_bound(days, change[:, i], span_end, kappa, momentum_over_a) for i in range(gm.size))
    return float(bound), displacement[-1]


def _cumulative_trapezoid(values, days):
    """∫ from days[0] to each days[j] (trapezoid), along axis 0; ``values`` (n,) or (n, k)."""
    steps = 0.5 * (values[1:] + values[:-1]) * np.diff(days).reshape((-1,) + (1,) * (values.ndim - 1))
    return np.concatenate([np.zeros((1,) + values.shape[1:]), np.cumsum(steps, axis=0)])


def _trapezoid(values, days):
    if days.size < 2:
        return 0.0
    return float(np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(days)))


def initial_rtol(error_share_rad):
    """First DOP853 rtol for an integration error share (rad), clipped to :data:`RTOL_RANGE`."""
    return float(np.clip(error_share_rad * RTOL_PER_ERROR, *RTOL_RANGE))


@dataclass(frozen=True)
class Decision:
    """One line of a plan: what was decided and why, in words and numbers."""

    topic: str
    choice: str
    reason: str


@dataclass
class PerturberEstimate:
    """Survey result for one perturber: closest distance (au) and the bound (rad) of leaving it out."""

    name: str
    closest_au: float
    bound_rad: float
    kept: bool


@dataclass
class Plan:
    """What :meth:`spinorbit.scene.Scene.run` will do, and why (``str(plan)`` reads like EXPLAIN).

    Attributes
    ----------
    route : {"torque-free", "one-way", "coupled"}
        Exact free motion (no integration), the one-way integration under the kept perturbers, or the
        fully coupled REBOUND run (BS, :class:`~spinorbit.coupling.rigid_body.CoupledRigidBody`).
    orbit_source : {"none", "de421", "ephemeris", "rebound"}
        Where the positions come from: none needed, DE421, a user ephemeris, a REBOUND (N-body) run.
    kept, dropped : tuple of str
        Perturbers in the run and left out.
    estimates : dict
        :class:`PerturberEstimate` per perturber (empty when nothing was surveyed).
    integrator : {"quaternion", "elements", "exact", "rebound-bs"}
    rtol : float or None
        First rtol of the integration (for "rebound-bs": BS eps_abs = eps_rel), refined a posteriori.
    end_only : bool
        Only the final state is asked: one output time, no dense output, quantities once.
    tolerance_rad : float
    kappa : float
        Measured attitude sensitivity of the free motion (module docstring).
    dropped_bound_rad : float
        Sum of the bounds of everything left out (for the torque-free route: all perturbers).
    full : bool
        True for the reference plan of ``Scene.plan(skip=False)``: nothing skipped.
    decisions : list of Decision
    samples : SampledPerturbers or None
        For a REBOUND orbit, the survey is taken at the run's sampling tolerance and kept here, so the
        N-body run is paid once; the run uses its kept perturbers' columns.
    back_reaction_rad : float
        Bound of the figure's back-reaction on the orbits that a one-way route leaves out (0 when
        it is not left out, or when the body has no mass in the orbit model).
    """

    route: str
    orbit_source: str
    kept: tuple
    dropped: tuple
    estimates: dict
    integrator: str
    rtol: float | None
    end_only: bool
    tolerance_rad: float
    kappa: float
    dropped_bound_rad: float
    full: bool
    decisions: list = field(default_factory=list)
    #: Perturber samples at the run's tolerance taken while planning (REBOUND route: the N-body run is
    #: then paid once), reused by the run for the kept perturbers.
    samples: object = field(default=None, repr=False)
    back_reaction_rad: float = 0.0
    back_reaction_bound_rad: float | None = None

    @property
    def integration_share_rad(self):
        """Tolerance left for integration and sampling once what was left out is paid for."""
        return self.tolerance_rad - self.dropped_bound_rad - self.back_reaction_rad

    def __str__(self):
        title = "reference plan (skip=False: nothing skipped)" if self.full else "plan"
        lines = [f"{title}: route {self.route}, orbits from {self.orbit_source}, integrator {self.integrator}"
                 + (f" (rtol {self.rtol:.1e})" if self.rtol else ""),
                 (f"  tolerance {self.tolerance_rad * ARCSEC_PER_RAD:.4g} arcsec ({self.tolerance_rad:.3e} rad); "
                  f"left out: bound {self.dropped_bound_rad * ARCSEC_PER_RAD:.3g} arcsec"
                  + (f" + back-reaction {self.back_reaction_rad * ARCSEC_PER_RAD:.3g} arcsec"
                     if self.back_reaction_rad else ""))]
        width = max(len(d.topic) for d in self.decisions) if self.decisions else 0
        for decision in self.decisions:
            lines.append(f"  -> {decision.topic.ljust(width)}  {decision.choice}")
            lines.append(f"     {' ' * width}  because {decision.reason}")
        return "\n".join(lines)
