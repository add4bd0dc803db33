"""The bounds the scene planner's skips rest on: what leaving out a torque or the back-reaction can do.

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
(:mod:`spinorbit.coupling.one_way`), at the loose relative tolerance :data:`~spinorbit.scene.tolerances.SURVEY_TOLERANCE` (with a
REBOUND orbit at the run's own tolerance, and kept for the run), which still tightens its grid around
close encounters. SAFETY = 2 covers the trapezoid rule between survey
samples and the linearisation. ``tests/test_scene.py`` checks the bound against full runs: the
measured effect of a dropped torque must stay below it. This *worst-attitude* bound is 20–2400×
above the measured effect: the real torque turns with the body, and its integral cancels.

The free-motion bound (what the planner uses where it applies)
---------------------------------------------------------------
The same linear response, with the cancellation kept where it is sound. The torque vector N(s) of each
perturber is evaluated along the exact free motion (:func:`free_motion_grid`: the torque-free solution
on a grid of :data:`POINTS_PER_TURN` points per turn at |ω| ≤ |L|/A plus every survey interval cut in
:data:`SURVEY_SUBDIVISION`; the perturber positions are the survey's Hermite interpolants, through the
one torque definition :func:`spinorbit.core.dynamics.equations.inertial_torques_along`). The response to a kick
splits in two:

- a **secular drift**, from the change of the free motion's frequencies, which depend on its two
  actions |L| and E only. Its kernel is (T − s) times constant derivatives of the frequencies, so
  integrating by parts is exact: the drift is ∫₀ᵀ (Ω_L δ|L|(s) + Ω_E δE(s)) ds with the first-order
  action changes δ|L|(s) = L̂·∫₀ˢ N ds' (the momentum change as a vector, in ICRF) and
  δE(s) = ∫₀ˢ ω·N ds' (the power), both integrated along the free motion with their cancellation
  (:func:`action_changes`). Ω_L, Ω_E are measured like κ (:func:`action_sensitivities`): κ_L with
  ω scaled by 1 + ε, κ_E with L turned in the body at fixed |L|, each the largest attitude change per
  unit action change and time;
- a **bounded part** (the tilt of L and the changed nutation: 2|δL|/|L| per kick). Its kernel turns
  with the body and shares the torque's frequencies (both live on the free motion's torus: the averaged
  potential shifts the phases without changing any action), so it does not cancel: it stays
  2 ∫|N|_max ds / |L| as in the worst-attitude bound.

So, with Ē(s) = ∫₀ˢ |N|_max/A ds' and Θ below (:func:`free_motion_torque_bound`),

    bound = SAFETY · [ κ_L ∫₀ᵀ (|δ|L||/A + 3Θ Ē) ds + κ_E ∫₀ᵀ (|δE − 2E δ|L|/|L|| / |L| + 6Θ Ē) ds
                       + 2 Ē(T) / (|L|/A) ],

taken at most equal to the worst-attitude bound (δE − 2E δ|L|/|L| is the energy change that the ω
scaling of κ_L does not account for). What it assumes:

- **The run stays near the free motion.** The run's torque is evaluated along the *run's* attitude,
  which every torque (kept and dropped) moves off the free motion by some Θ; an attitude error ε changes
  the degree-2 torque by at most ATTITUDE_GRADIENT · |N|_max · ε (3: 2 from turning r̂ in the body,
  1 from turning N into the inertial frame), hence the Θ terms (the power's carries |ω| ≤ |L|/A and
  2E/|L|² ≤ 1/A, so 6). Θ is the smallest self-consistent total of the perturbers' bounds
  (:func:`self_consistent_deviation`), plus the survey's relative position error (it enters like an
  attitude error). Above :data:`LINEAR_LIMIT` = 0.1 rad (e.g. the Earth at an Apophis flyby, which
  turns the spin by radians; the Earth's torque on the Moon) the torque along the free motion says
  nothing about the run's, and every perturber gets the worst-attitude bound.
- **Linear response**, as the worst-attitude bound: κ_L, κ_E are measured for kicks at the epoch and
  taken for every s; the trapezoid rule on the grid and the rest are left to SAFETY = 2. Checked
  against full runs (``tests/test_scene.py``): short-axis, long-axis, near-separatrix, slowly rotating
  and flat-disc (C ≈ A + B: the torque's body frequency at the nutation frequency) states, and a close
  flyby; 3.7–39× above the measured effect where the worst-attitude bound was 19–2600×
  (``docs/scenes.md``).
- **Resolution.** Beyond :data:`MAX_EVALUATIONS` = 2e6 torque evaluations (grid points × perturbers)
  the worst-attitude bound is used; the plan's reason says which bound was taken and why.

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
REBOUND run (``CoupledRigidBody``, ``tests/test_scene.py``). It keeps the worst-attitude form: the chain
bounds only the *size* of the displacement, not its direction, so there is no torque-change vector to
integrate along the free motion.

How the tolerance is shared between what is left out and the integration: :mod:`spinorbit.scene.tolerances`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ORBIT_RESPONSE",
    "SAFETY",
    "FreeMotion",
    "action_changes",
    "action_sensitivities",
    "attitude_sensitivities",
    "attitude_sensitivity",
    "back_reaction_bound",
    "dropped_torque_bound",
    "dropped_torque_bounds",
    "free_motion_bounds",
    "free_motion_grid",
    "free_motion_torque_bound",
    "max_torque_over_a",
    "self_consistent_deviation",
]

#: Factor on the linear-response bound (module docstring).
SAFETY = 2.0
#: Horizons (fractions of the span) at which the attitude sensitivity κ is measured.
SENSITIVITY_HORIZONS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 1.0)
#: Attitude change (rad) the sensitivity probe aims for: large against rounding (1e-13), small
#: enough to stay linear.
SENSITIVITY_PROBE_RAD = 1e-6
#: Largest orbit displacement per unit impulse and elapsed time (module docstring: 3.91 for a circular
#: orbit, computed from Hill's equations; rounded up).
ORBIT_RESPONSE = 4.0
#: Free-motion bound: grid points per turn of the fastest rotation the free motion can reach (|ω| ≤ |L|/A);
#: the degree-2 torque, quadratic in the perturber's body direction, then has ≥ 16 points per cycle.
POINTS_PER_TURN = 32
#: Free-motion bound: each survey interval is cut into this many (the survey grid is dense where the
#: perturbers move fast, e.g. close encounters).
SURVEY_SUBDIVISION = 4
#: Free-motion bound: largest number of torque evaluations (grid points × perturbers; ≈ 0.1 µs each);
#: beyond it the worst-attitude bound is used.
MAX_EVALUATIONS = 2_000_000
#: Free-motion bound: largest deviation (rad) of the run from the free motion for which the torques
#: are evaluated along the free motion; beyond it the worst-attitude bound is used.
LINEAR_LIMIT = 0.1
#: |δN| ≤ ATTITUDE_GRADIENT · |N|_max · ε when the attitude is off by ε: 2 from turning r̂ in the body
#: (|δ(r̂ × I′r̂)| ≤ (C − A)|δr̂|), 1 from turning N into the inertial frame.
ATTITUDE_GRADIENT = 3.0
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
    :func:`attitude_sensitivities` of the one state.
    """
    return float(attitude_sensitivities([state], span_days)[0])


def attitude_sensitivities(states, span_days):
    """κ of :func:`attitude_sensitivity` for many states: every state and its three kicked states in one
    vectorised exact flow (:func:`spinorbit.core.free_motion.members.free_flow_each`).

    The angle between two attitudes is the same in principal and user axes, so it is taken between the
    principal-axis attitudes. A state's κ depends on its own flows only: the same bits alone and among
    any others (the ensemble's batch route takes a group's κ from one call). InvalidStateError for a
    state whose flow over the span would leave the free flow's domain.
    """
    from spinorbit.core.math.rotations import rotation_angle_between_many

    states = list(states)
    n = len(states)
    horizons = np.array(SENSITIVITY_HORIZONS) * span_days
    kick = SENSITIVITY_PROBE_RAD / span_days
    starts = [state.principal_flow_start(float(horizons[-1])) for state in states]
    p = np.array([state.body.to_principal for state in states])
    values = np.array([state.body.moment_values for state in states])
    kicked = np.repeat(np.array([state.angular_velocity_rad_per_day for state in states])[:, None, :], 3, axis=1)  # rad/day
    kicked[:, range(3), range(3)] += kick  # ω kicked along each user body axis
    momenta = np.empty((n, 4, 3))
    momenta[:, :3] = np.matmul(p[:, None], (values[:, None, :] * kicked)[..., None])[..., 0]  # P (I ω) per row
    momenta[:, 3] = [momentum for _, momentum in starts]  # then the state itself
    quaternions = np.repeat(np.array([q for q, _ in starts])[:, None, :], 4, axis=1)
    moments = np.repeat(np.array([state.body.principal_moments for state in states])[:, None, :], 4, axis=1)
    flowed = _free_flows(quaternions.reshape(-1, 4), momenta.reshape(-1, 3), moments.reshape(-1, 3),
                         horizons).reshape(n, 4, horizons.size, 4)
    base = np.ascontiguousarray(np.broadcast_to(flowed[:, 3:], (n, 3, horizons.size, 4))).reshape(-1, 4)
    angles = rotation_angle_between_many(base, np.ascontiguousarray(flowed[:, :3]).reshape(-1, 4))
    largest = np.max(angles.reshape(n, 3, horizons.size) / (kick * horizons), axis=2)  # (n, axis)
    kappas = np.ones(n)
    for axis in range(3):  # max(κ, largest) in Python's sense: a NaN axis leaves κ as it was
        kappas = np.where(largest[:, axis] > kappas, largest[:, axis], kappas)
    return kappas


def _free_flows(quaternions, momenta, moments, horizons):
    """Principal-axis attitudes (N, K, 4) of N states (principal quaternions, momenta and moments) flowed
    exactly to the K ``horizons``: one compiled loop, each state on its own."""
    from spinorbit.core.free_motion.members import free_flow_each

    n = len(quaternions)
    q_out, m_out = np.empty((n, horizons.size, 4)), np.empty((n, horizons.size, 3))
    free_flow_each(np.array(quaternions, dtype=float), np.array(momenta, dtype=float),
                   np.array(moments, dtype=float), np.ascontiguousarray(np.broadcast_to(horizons, (n, horizons.size))),
                   q_out, m_out)
    return q_out


def dropped_torque_bound(days, torque_over_a, span_end, kappa, momentum_over_a):
    """The attitude bound (rad) at ``span_end`` of leaving out a torque |N|/A sampled at ``days``.

    ``days`` (increasing, TDB days) and ``torque_over_a`` (rad/day²) are survey samples; the integrals
    of the module docstring are taken with the trapezoid rule. ``momentum_over_a`` is |L|/A (rad/day).
    """
    torque = np.asarray(torque_over_a, dtype=float)
    return float(dropped_torque_bounds(days, torque[None, :], span_end, kappa, momentum_over_a)[0])


def dropped_torque_bounds(days, torque_over_a, span_end, kappa, momentum_over_a):
    """:func:`dropped_torque_bound` of many bodies on one survey: ``torque_over_a`` (N, n) at ``days`` (n,),
    ``kappa`` and ``momentum_over_a`` scalars or (N,). Returns (N,) bounds (rad), each row's the bits of its
    own call (the trapezoid sums run along each row)."""
    days = np.asarray(days, dtype=float)
    n = np.asarray(torque_over_a, dtype=float)
    lever = span_end - days
    drift = _trapezoid_rows(lever * n, days)
    tilt = _trapezoid_rows(n, days)
    return SAFETY * (kappa * drift + 2.0 * tilt / momentum_over_a)


@dataclass
class FreeMotion:
    """The exact free motion on the grid of the free-motion bound (:func:`free_motion_grid`).

    Attributes
    ----------
    days : ndarray (n,)
        TDB days, increasing, from the epoch to the span's end.
    quaternions : ndarray (n, 4)
        Principal-axis attitudes (body → ICRF).
    omega : ndarray (n, 3)
        Angular velocity in ICRF, rad/day.
    momentum_over_a : ndarray (3,)
        L/A in ICRF (constant on the free motion), rad/day.
    energy_over_a : float
        Kinetic energy E/A = ½ L·ω / A, rad²/day².
    """

    days: np.ndarray
    quaternions: np.ndarray
    omega: np.ndarray
    momentum_over_a: np.ndarray
    energy_over_a: float


def free_motion_grid(state, epoch_day, span_end, survey_days=(), perturbers=1):
    """The exact free motion of ``state`` on the grid of the free-motion bound, or why not.

    The grid takes :data:`POINTS_PER_TURN` points per 2π A/|L| (a turn at the largest angular velocity
    the free motion can reach, |ω| ≤ |L|/A) and every survey interval cut into
    :data:`SURVEY_SUBDIVISION` (the survey tightened its grid where the perturbers move fast, e.g. at
    a close encounter). Returns ``(FreeMotion, None)``, or ``(None, why)`` when the grid times
    ``perturbers`` would exceed :data:`MAX_EVALUATIONS` torque evaluations.
    """
    from spinorbit.core.free_motion.flow import torque_free_states
    from spinorbit.core.math.rotations import attitude_to_quat, quat_to_attitude_many

    attitude, momentum = state.principal_attitude_and_momentum()
    moments = np.array(state.body.principal_moments, dtype=float)
    turn = 2.0 * math.pi * moments[0] / float(np.linalg.norm(momentum))
    uniform = int(math.ceil((span_end - epoch_day) / turn * POINTS_PER_TURN)) + 1
    survey_days = np.asarray(survey_days, dtype=float)
    total = uniform + SURVEY_SUBDIVISION * max(survey_days.size - 1, 0)
    if total * perturbers > MAX_EVALUATIONS:
        return None, (f"the free-motion grid would take {total * perturbers:.3g} torque evaluations "
                      f"(> {MAX_EVALUATIONS:.0e}: {POINTS_PER_TURN} per turn of a {turn * 24:.3g} h rotation), "
                      "so the worst-attitude bound is used")
    pieces = [np.linspace(epoch_day, span_end, max(uniform, 2))]
    if survey_days.size > 1:
        fractions = np.arange(SURVEY_SUBDIVISION) / SURVEY_SUBDIVISION
        pieces.append((survey_days[:-1, None] + np.diff(survey_days)[:, None] * fractions).ravel())
    days = np.unique(np.clip(np.concatenate(pieces), epoch_day, span_end))
    quaternions, body_momenta = torque_free_states(attitude_to_quat(np.ascontiguousarray(attitude)), momentum,
                                                   *moments, days - epoch_day)
    quaternions = np.ascontiguousarray(quaternions)
    # ω_inertial = M(q) ω_body, M(q) the transpose of the attitude matrix.
    omega = np.einsum("nji,nj->ni", quat_to_attitude_many(quaternions), body_momenta / moments)
    momentum_over_a = attitude.T @ momentum / moments[0]
    energy_over_a = 0.5 * float(momentum @ (momentum / moments)) / moments[0]
    return FreeMotion(days, quaternions, omega, momentum_over_a, energy_over_a), None


def action_changes(free, source, moments):
    """δ|L|/A and δE/A along the free motion from the torque of ``source``, cancellation kept.

    δL(s) = ∫₀ˢ N ds' is integrated as a vector (ICRF) along ``free``; δ|L| = L̂·δL and the kinetic
    energy change δE(s) = ∫₀ˢ ω·N ds' are the first-order changes of the free motion's two actions
    (its frequencies depend on |L| and E only). Trapezoid rule on ``free.days``.

    Parameters
    ----------
    free : FreeMotion
    source : ndarray
        One :mod:`spinorbit.core.model.perturbers` source (sampled, fixed or Kepler), evaluated through the one
        torque definition (:func:`spinorbit.core.dynamics.equations.inertial_torques_along`).
    moments : (A, B, C)
        Principal moments (only ratios enter).

    Returns
    -------
    momentum : ndarray (n,)
        δ|L|/A, rad/day.
    energy : ndarray (n,)
        δE/A, rad²/day².
    """
    from spinorbit.core.dynamics.equations import inertial_torques_along, make_model

    torque = inertial_torques_along(free.days, free.quaternions, make_model(moments, [source])) / moments[0]
    direction = free.momentum_over_a / np.linalg.norm(free.momentum_over_a)
    return (_cumulative_trapezoid(torque @ direction, free.days),
            _cumulative_trapezoid(np.einsum("ni,ni->n", free.omega, torque), free.days))


def action_sensitivities(state, span_days):
    """(κ_L, κ_E): the largest attitude change per unit action change and time of the exact free motion.

    κ_L: ω scaled by 1 + ε (δ|L| = ε|L| and δE = 2εE: the free motion runs faster), per δ|L|/A · τ.
    κ_E: the body momentum turned in the body at fixed |L| towards the component of ω across L (E changes
    fastest), per |δE|/|L| · τ (δE measured exactly, so a state with ω along L, where E changes only to
    second order, is measured too). Horizons τ and probe size as in :func:`attitude_sensitivity`.
    """
    from spinorbit.core.math.rotations import rotation_angle_between_many

    horizons = np.array(SENSITIVITY_HORIZONS) * span_days
    q, momentum = state.principal_flow_start(float(horizons[-1]))
    moments = np.array(state.body.principal_moments, dtype=float)
    size = float(np.linalg.norm(momentum))
    omega = momentum / moments
    energy = 0.5 * float(momentum @ omega)
    eps = SENSITIVITY_PROBE_RAD / (span_days * float(np.linalg.norm(omega)))
    across = omega - (omega @ momentum) / size**2 * momentum
    across_size = float(np.linalg.norm(across))
    if across_size < 1e-9 * np.linalg.norm(omega):  # ω along L: E changes at second order, any direction across
        across = np.cross(momentum, np.eye(3)[int(np.argmin(np.abs(momentum)))])
    across /= np.linalg.norm(across)
    # Turn by an angle whose energy change is the probe's, δE/|L| · T ≈ SENSITIVITY_PROBE_RAD (δE ≈ |L| |ω⊥| angle).
    angle = min(SENSITIVITY_PROBE_RAD / (span_days * max(across_size, 1e-300)), 1e-3)
    turned = math.cos(angle) * momentum + math.sin(angle) * size * across
    change = abs(0.5 * float(turned @ (turned / moments)) - energy)
    # the state, ω scaled and L turned: one vectorised exact flow
    base, scaled, other = _free_flows([q] * 3, [momentum, momentum * (1.0 + eps), turned], [moments] * 3, horizons)
    kappa_l = float(np.max(rotation_angle_between_many(base, scaled) / horizons / (eps * size / moments[0])))
    kappa_e = (float(np.max(rotation_angle_between_many(base, other) / horizons / (change / size))) if change > 0.0
               else 1.0)
    return kappa_l, kappa_e


def free_motion_torque_bound(free, momentum, energy, envelope, kappa_l, kappa_e, deviation):
    """The attitude bound (rad) at ``free.days[-1]`` of leaving out a torque, from its action changes.

    bound = SAFETY · [ κ_L ∫₀ᵀ (|δ|L||/A + 3Θ Ē) ds + κ_E ∫₀ᵀ (|δE − (2E/|L|) δ|L||/|L| + 6Θ Ē) ds
                       + 2 Ē(T) / (|L|/A) ],       Ē(s) = ∫₀ˢ |N|_max/A ds'  (module docstring).

    Parameters
    ----------
    free : FreeMotion
    momentum, energy : ndarray (n,)
        δ|L|/A and δE/A from :func:`action_changes`.
    envelope : ndarray (n,)
        Ē at ``free.days`` (worst attitude), rad/day.
    kappa_l, kappa_e : float
        From :func:`action_sensitivities`.
    deviation : float
        Θ: bound (rad) on how far the run's attitude strays from the free motion over the span.
    """
    days = free.days
    size = float(np.linalg.norm(free.momentum_over_a))
    envelope = np.asarray(envelope, dtype=float)
    rest = energy - 2.0 * free.energy_over_a / size * momentum  # δE not explained by the change of |L|
    drift = (kappa_l * _trapezoid(np.abs(momentum) + ATTITUDE_GRADIENT * deviation * envelope, days)
             + kappa_e * _trapezoid(np.abs(rest) / size + 2.0 * ATTITUDE_GRADIENT * deviation * envelope, days))
    return SAFETY * (drift + 2.0 * float(envelope[-1]) / size)


def self_consistent_deviation(free_motion, worst_attitude, gradient):
    """Smallest Θ with Θ = Σᵢ min(bᵢ + gradient · Θ · wᵢ, wᵢ), or None when it exceeds :data:`LINEAR_LIMIT`.

    ``free_motion`` are the bounds bᵢ of :func:`free_motion_torque_bound` at Θ = 0, ``worst_attitude``
    the bounds wᵢ of :func:`dropped_torque_bound` (rad). The torques move the run off the free motion
    by Θ, and the Θ terms of the free-motion bound are at most ``gradient`` · Θ · wᵢ (the same integrals
    as wᵢ; ``gradient`` = 3 max(1, (κ_L + 2κ_E)/κ)), so the iteration from Θ = Σ min(bᵢ, wᵢ) increases
    monotonically to the smallest fixed point.
    """
    b, w = np.asarray(free_motion, dtype=float), np.asarray(worst_attitude, dtype=float)
    theta = float(np.sum(np.minimum(b, w)))
    for _ in range(200):
        if theta > LINEAR_LIMIT:
            return None
        new = float(np.sum(np.minimum(b + gradient * theta * w, w)))
        if new <= theta * (1.0 + 1e-9):
            return max(new, theta)
        theta = new
    return theta if theta <= LINEAR_LIMIT else None


def free_motion_bounds(state, epoch_day, span_end, perturbers, worst, position_error, kappa):
    """The free-motion bounds (rad) of a scene's perturbers, each at most its worst-attitude bound; and the words.

    Parameters
    ----------
    state : spinorbit.RotationState
        The body at ``epoch_day``.
    epoch_day, span_end : float
        TDB days.
    perturbers : sequence of (source, days, torque_over_a)
        Per perturber: its :mod:`spinorbit.core.model.perturbers` source, its survey times (TDB days) and
        |N|_max/A on them (rad/day², :func:`max_torque_over_a`).
    worst : sequence of float
        Their worst-attitude bounds (:func:`dropped_torque_bound`), rad.
    position_error : float
        The survey's relative position error (it enters like an attitude error).
    kappa : float
        :func:`attitude_sensitivity`.

    Returns
    -------
    bounds : list of float
        ``worst`` itself where the free-motion bound does not apply (module docstring: the grid above
        :data:`MAX_EVALUATIONS`, or the run more than :data:`LINEAR_LIMIT` off the free motion).
    note : str
        Which bound was taken, with its numbers, for the plan.
    """
    span = span_end - epoch_day
    formula = (f"worst attitude: 2 [κ ∫(T-s)|N|/A ds + 2∫|N| ds/|L|], |N| ≤ 3μ(C-A)/2r³, κ = {kappa:.3g} "
               f"(measured on the free motion), T = {span:.6g} d")
    free, why = free_motion_grid(state, epoch_day, span_end, np.unique(np.concatenate([p[1] for p in perturbers])),
                                 len(perturbers))
    if free is None:
        return list(worst), f"{formula}; {why}"
    kappa_l, kappa_e = action_sensitivities(state, span)
    moments = state.body.principal_moments
    changes = [action_changes(free, source, moments) for source, _, _ in perturbers]
    envelopes = [np.interp(free.days, days, _cumulative_trapezoid(np.asarray(n, dtype=float), days))
                 for _, days, n in perturbers]

    def bounds_at(deviation):
        return [free_motion_torque_bound(free, dl, de, e, kappa_l, kappa_e, deviation)
                for (dl, de), e in zip(changes, envelopes)]

    deviation = self_consistent_deviation(bounds_at(0.0), worst,
                                          ATTITUDE_GRADIENT * max(1.0, (kappa_l + 2.0 * kappa_e) / kappa))
    if deviation is None:
        return list(worst), (f"{formula}; the perturbers move the attitude by more than {LINEAR_LIMIT:g} rad from "
                             "the free motion (worst-attitude bounds), so the torque along the free motion is not "
                             "the torque of the run: the worst-attitude bound is used")
    deviation += position_error
    bounds = [min(b, w) for b, w in zip(bounds_at(deviation), worst)]
    return bounds, (f"free motion: 2 [κ_L ∫|δ|L||/A ds + κ_E ∫|δE - 2E δ|L|/|L||/|L| ds + 2∫|N|_max ds/|L|], "
                    f"δ|L| and δE the action changes of the torque integrated along the exact free motion "
                    f"({free.days.size} points, {POINTS_PER_TURN} per turn), κ_L = {kappa_l:.3g}, "
                    f"κ_E = {kappa_e:.3g}, the run within {deviation:.2g} rad of the free motion; at most the "
                    f"{formula}")


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


def _trapezoid_rows(values, days):
    """:func:`_trapezoid` of each row of ``values`` (N, n) (numpy's pairwise sum along each row, as of one row)."""
    if days.size < 2:
        return np.zeros(values.shape[0])
    return np.sum(0.5 * (values[:, 1:] + values[:, :-1]) * np.diff(days), axis=1)
