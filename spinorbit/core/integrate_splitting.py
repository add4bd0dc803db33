"""Symplectic splitting integrators: the exact torque-free flow alternated with torque kicks.

The split (Touma & Wisdom 1994, AJ 107, 1189; Celledoni, Fassò, Säfström & Zanna 2008, SIAM J. Sci.
Comput. 30, 2084, whose splitting of the free part we do not need because the free part is exact here)
-----------------------------------------------------------------------------------------------------
In the extended phase space (attitude, body momentum M, time t and its conjugate p_t) the Hamiltonian
of a rigid body in an external field is

    H = A + B,   A = T(M) + p_t = ½ (M_x²/A + M_y²/B + M_z²/C) + p_t,   B = −U(t, attitude),

with U the force function of :mod:`spinorbit.core.dynamics` (U = −potential energy). Both parts have
exact flows:

* **drift** (flow of A over τ): the torque-free motion from (q, M) for a time τ, and t += τ. It is
  the closed form of :mod:`spinorbit.core.torque_free` (Fukushima's canonical elements, paper eq. 12),
  exact to rounding for every mode (SAM, LAM, separatrix, uniform rotation);
* **kick** (flow of B over τ): the attitude and t are frozen, so the torque N(t, q) is constant and
  the body momentum changes by M ← M + τ N (body frame; δU = N·δθ, ``docs/torques.md``). The
  inertial angular momentum changes by τ R N, the attitude not at all.

A composition of exact flows of the two parts is a symplectic map of the extended phase space. For a
time-independent perturber (p_t irrelevant) it conserves a modified energy within O(τ^p) of E = T − U
for exponentially long times, so the energy error is bounded and does not drift (tested over 1e5 and
1e6 steps). Symplecticity holds for a *fixed* step only: this module has no variable-step mode (a
step-doubling controller would break it, and a symplectic time transformation would need a
Poincaré-transformed Hamiltonian whose parts have no exact flows here). Steps are shortened only
to land on the requested output times: the step in each output interval is the interval divided by
ceil(interval / step), so within one interval the map is one symplectic map iterated.

Schemes (coefficients per step of length τ: drift c₀τ, kick d₀τ, drift c₁τ, …, kick d_{m−1}τ,
drift c_mτ; consecutive drifts of neighbouring steps are merged into one torque-free evaluation)
----------------------------------------------------------------------------------------------------
``strang``   leapfrog drift-kick-drift (Strang 1968), order 2: c = (½, ½), d = (1).
``yoshida4`` Yoshida's (1990, Phys. Lett. A 150, 262) triple jump of ``strang`` with
             w₁ = 1/(2 − 2^{1/3}), w₀ = −2^{1/3}/(2 − 2^{1/3}): order 4 whatever the size of B.
``saba2``    Laskar & Robutel (2001, Celest. Mech. Dyn. Astron. 80, 39), Table 1:
             c₁ = ½ − √3/6, c₂ = √3/3, d₁ = ½ (c = (c₁, c₂, c₁), d = (d₁, d₁)).
``saba3``    same paper: c₁ = ½ − √15/10, c₂ = √15/10, d₁ = 5/18, d₂ = 4/9
             (c = (c₁, c₂, c₂, c₁), d = (d₁, d₂, d₁)).
``sbab2``    same paper: d₁ = 1/6, d₂ = 2/3, c₂ = ½ (kick-first: c = (0, ½, ½, 0), d = (d₁, d₂, d₁)).

For H = A + εB the SABA_n/SBAB_n error after a fixed time is O(ε τ^{2n} + ε² τ²): the schemes kill
every error term of first order in ε up to τ^{2n}, but are only 2nd order in the ε² terms. With the
weak torques of asteroid and planetary spin (ε ~ 1e-4 … 1e-10 relative to the free motion) the
ε τ^{2n} term dominates down to τ ~ ε^{1/(2n−2)}, so SABA2 behaves like a 4th-order method with two
torque-free evaluations per step. Orders measured in ``tests/test_integrate_splitting.py`` and
``docs/splitting.md``.

Cost: one drift is one setup of the free motion from (q, M) (:func:`relative_flow_constants`, double
precision, no attitude-to-elements step) plus two :func:`.torque_free.evaluate_flow` (the relative
rotation); one kick is one torque evaluation (a Kepler solve per Keplerian perturber). The setup
dominates: measured 1.7 µs per drift + kick against 3.2 µs with the double-double
:func:`.torque_free.flow_constants` (``docs/splitting.md``).
"""

import math

import numpy as np

from ._jit import jit
from .dynamics import (
    MODEL_PERTURBERS,
    STATE_SIZE,
    force_function_and_torque_xyz,
    validate_state,
)
from .gravity_field import BODY_A, BODY_B, BODY_C
from .integrate_quaternion import _validate_times
from .perturbers import sampled_span
from .canonical import (
    MO_MODE,
    MO_PARAM_C,
    MODE_SAM,
    MODE_UNIFORM,
    amplitude_from_momentum,
    elliptic_constants,
    flip_signs,
    inertia_constants,
    motion_from_momentum,
)
from .ddouble import two_prod
from .elliptic import ellipf_k, pn_k
from .torque_free import (
    FL_ARG0,
    FL_FLIP,
    FL_FLIP_X,
    FL_FLIP_Y,
    FL_FLIP_Z,
    FL_G_CONST_HI,
    FL_G_CONST_LO,
    FL_G_RATE_HI,
    FL_KAPPA_HI,
    FL_M0_X,
    FL_M0_Y,
    FL_M0_Z,
    FL_MODE,
    FL_PERIODIC,
    FL_QN_W,
    FL_RATE_HI,
    FLOW_SIZE,
    _qmul,
    evaluate_flow,
    flow_constants,
)

# ---------------------------------------------------------------------------------------------
# Scheme coefficients

_W1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
_W0 = -(2.0 ** (1.0 / 3.0)) / (2.0 - 2.0 ** (1.0 / 3.0))
_SABA2_C1 = 0.5 - math.sqrt(3.0) / 6.0
_SABA2_C2 = math.sqrt(3.0) / 3.0
_SABA3_C1 = 0.5 - math.sqrt(15.0) / 10.0
_SABA3_C2 = math.sqrt(15.0) / 10.0

#: name → (drift coefficients c₀..c_m, kick coefficients d₀..d_{m−1}); Σc = Σd = 1.
SCHEMES = {
    "strang": ((0.5, 0.5), (1.0,)),
    "yoshida4": ((0.5 * _W1, 0.5 * (_W1 + _W0), 0.5 * (_W0 + _W1), 0.5 * _W1), (_W1, _W0, _W1)),
    "saba2": ((_SABA2_C1, _SABA2_C2, _SABA2_C1), (0.5, 0.5)),
    "saba3": ((_SABA3_C1, _SABA3_C2, _SABA3_C2, _SABA3_C1), (5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0)),
    "sbab2": ((0.0, 0.5, 0.5, 0.0), (1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0)),
}

#: Nominal order in τ of each scheme when the perturbation is not small (ε ~ 1), and the order of the
#: O(ε τ^{2n}) term that dominates for weak perturbations (Laskar & Robutel 2001).
NOMINAL_ORDER = {"strang": 2, "yoshida4": 4, "saba2": 2, "saba3": 2, "sbab2": 2}
WEAK_PERTURBATION_ORDER = {"strang": 2, "yoshida4": 4, "saba2": 4, "saba3": 6, "sbab2": 4}

#: A requested step that divides an output interval up to rounding must not add a step: the number of
#: steps is ceil(interval/step − STEP_COUNT_SLACK). 1e-9 is far above the rounding of the quotient
#: (a few ε) and far below any meaningful fraction of a step.
STEP_COUNT_SLACK = 1e-9

#: Size of the scratch array of :func:`drift` (two quaternions and two momenta).
DRIFT_SCRATCH_SIZE = 14

# Indices of the counters returned by the kernel.
STAT_STEPS, STAT_DRIFTS, STAT_KICKS = 0, 1, 2


# ---------------------------------------------------------------------------------------------
# A cheaper setup of the torque-free flow for short drifts

#: The short-drift setup rounds pn(arg) to a double, an error of ε κ |arg| rad in g per drift
#: (κ = (a − c) G/ν, large for nearly symmetric bodies). Above this bound on κ (|arg| ≤ a few K ~ 1–10)
#: the drift takes the double-double setup instead: κ ≤ 100 keeps that error ≤ ~1e-13 rad per drift,
#: against the ≈ 5e-15 rad round-trip error of either setup measured for moderate κ.
SHORT_SETUP_KAPPA_LIMIT = 100.0


@jit
def relative_flow_constants(quaternion, momentum, big_a, big_b, big_c):
    """Flow constants of the torque-free motion *up to a constant rotation*, in double precision.

    For :func:`drift` only, which uses the flow as the relative rotation q_f(0)⁻¹ ⊗ q_f(τ). With the
    closed form q_f(t) = Q_n ⊗ q_z(g) ⊗ q_x(J) ⊗ q_z(l) ⊗ F (node frame Q_n, Andoyer angles, flip F),
    that product does not depend on Q_n nor on the constant part of g. So the node frame is set to the
    identity and g(0) = 0: no attitude-to-elements step (node angles, attitude matrix, node-frame
    quaternion — ≈ 1 µs, the largest part of :func:`.torque_free.flow_constants`).

    And short drifts need no long-span machinery: :func:`.torque_free.flow_constants` forms the rates
    ν, c G, κ in double-double and the half period and the advance of g per half period by a
    double-double AGM, so that one set of constants serves 1e5 time units. A drift lasts a fraction
    of a rotation; rounding ν to a double costs ε ν τ rad. Here ν, c G, κ are doubles from the body
    momentum, the kernels' constants come from :func:`.canonical.elliptic_constants`, and
    :func:`.torque_free.evaluate_flow` takes its non-periodic branch (the elliptic kernels reduce the
    argument themselves). Uniform rotations, the separatrix and large κ (nearly symmetric bodies,
    :data:`SHORT_SETUP_KAPPA_LIMIT`) take the full setup, which is also valid for the relative use.

    Parameters and returns as :func:`.torque_free.flow_constants`; the quaternions it yields are the
    true attitudes times an unknown constant rotation on the left.
    """
    ic = inertia_constants(big_a, big_b, big_c)
    mo, flip = motion_from_momentum(momentum[0], momentum[1], momentum[2], ic)
    mode = int(mo[MO_MODE])
    a_b, b_c, a_c = ic[3], ic[4], ic[5]
    if mode == MODE_UNIFORM or mo[MO_PARAM_C] == 0.0:  # uniform rotation or separatrix: full setup
        return flow_constants(quaternion, momentum, big_a, big_b, big_c)
    fx, fy, fz = flip_signs(flip)
    mx, my, mz = fx * momentum[0], fy * momentum[1], fz * momentum[2]
    big_g = math.sqrt(mx * mx + my * my + mz * mz)
    if mode == MODE_SAM:
        nu = math.sqrt((a_b * my * my + a_c * mz * mz) * b_c)
    else:
        nu = math.sqrt((a_c * mx * mx + b_c * my * my) * a_b)
    kappa = a_c * big_g / nu
    if not kappa <= SHORT_SETUP_KAPPA_LIMIT:
        return flow_constants(quaternion, momentum, big_a, big_b, big_c)
    mk, pk = elliptic_constants(mo)
    flow = np.zeros(FLOW_SIZE)
    flow[FL_MODE] = mode
    flow[FL_FLIP] = flip
    flow[FL_FLIP_X], flow[FL_FLIP_Y], flow[FL_FLIP_Z] = fx, fy, fz
    flow[FL_M0_X], flow[FL_M0_Y], flow[FL_M0_Z] = momentum[0], momentum[1], momentum[2]
    arg0 = ellipf_k(amplitude_from_momentum(mx, my, mz, mo, ic), mk)
    flow[FL_QN_W] = 1.0  # identity node frame (cancels in the relative rotation)
    flow[FL_ARG0] = arg0
    flow[FL_PERIODIC] = 0.0
    flow[FL_RATE_HI] = nu
    flow[FL_G_RATE_HI] = big_g / big_c
    flow[FL_KAPPA_HI] = kappa
    # g(0) = 0: constant −κ pn(arg0), kept as the exact double-double product of the two doubles
    ch, cl = two_prod(-kappa, pn_k(arg0, mk, pk))
    flow[FL_G_CONST_HI], flow[FL_G_CONST_LO] = ch, cl
    return flow, mo, mk, pk


# ---------------------------------------------------------------------------------------------
# The two exact flows


@jit
def drift(tau, q, m, big_a, big_b, big_c, short_setup, scratch):
    """Exact torque-free flow over τ, in place: q (unit quaternion, body → inertial), m (body momentum).

    The flow is applied as a *relative* rotation: q ← q ⊗ (q_f(0)⁻¹ ⊗ q_f(τ)), M ← M + (M_f(τ) − M_f(0)),
    where q_f, M_f are the closed form from the elements of (q, M). The round trip (q, M) → elements →
    (q_f(0), M_f(0)) is off by a few ε in a direction that repeats from drift to drift (measured
    ≈ 5e-15 rad per drift, growing linearly over 1e5 drifts); the relative form cancels that common
    error at the cost of one more evaluation (≈ 0.3 µs). M = 0 is no rotation at all. q is
    renormalised (the projection does not change the attitude). ``scratch`` is a preallocated (14,)
    array (no allocation per drift in the loop); ``short_setup`` selects :func:`relative_flow_constants`.
    """
    if m[0] == 0.0 and m[1] == 0.0 and m[2] == 0.0:
        return
    if short_setup:
        flow, mo, mk, pk = relative_flow_constants(q, m, big_a, big_b, big_c)
    else:
        flow, mo, mk, pk = flow_constants(q, m, big_a, big_b, big_c)
    q_start = scratch[0:4]
    m_start = scratch[4:7]
    q_end = scratch[7:11]
    m_end = scratch[11:14]
    evaluate_flow(0.0, flow, mo, mk, pk, q_start, m_start)
    evaluate_flow(tau, flow, mo, mk, pk, q_end, m_end)
    # relative body-frame rotation r = q_f(0)⁻¹ ⊗ q_f(τ)
    r = _qmul(q_start[0], -q_start[1], -q_start[2], -q_start[3], q_end[0], q_end[1], q_end[2], q_end[3])
    q0, q1, q2, q3 = _qmul(q[0], q[1], q[2], q[3], r[0], r[1], r[2], r[3])
    norm = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    q[0], q[1], q[2], q[3] = q0 / norm, q1 / norm, q2 / norm, q3 / norm
    for i in range(3):
        m[i] += m_end[i] - m_start[i]


@jit
def kick(t, tau, q, m, model):
    """Exact flow of −U over τ at frozen attitude and time, in place: M ← M + τ N(t, q) (body frame)."""
    _, nx, ny, nz = force_function_and_torque_xyz(t, q[0], q[1], q[2], q[3], model)
    m[0] += tau * nx
    m[1] += tau * ny
    m[2] += tau * nz


# ---------------------------------------------------------------------------------------------
# The compiled loop


@jit
def integrate_splitting_kernel(y0, t0, t_out, model, step, drift_coeffs, kick_coeffs, short_setup):
    """Fixed-step splitting from (t0, y0), landing on every output time.

    Parameters
    ----------
    y0 : ndarray (7,)
        (q0, q1, q2, q3, ωx, ωy, ωz), q normalised by the caller; ω body frame, rad per time unit.
    t0 : float
        Initial time (time unit of the model).
    t_out : ndarray (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        Model array of :mod:`spinorbit.core.dynamics` (principal moments A ≤ B ≤ C).
    step : float
        Largest step (> 0, time unit); each output interval is cut into ceil(|interval|/step) equal
        steps.
    drift_coeffs, kick_coeffs : ndarray
        Scheme coefficients (:data:`SCHEMES`), len(drift_coeffs) = len(kick_coeffs) + 1.
    short_setup : bool
        Set up each drift with :func:`relative_flow_constants` (double precision) instead of
        :func:`.torque_free.flow_constants` (double-double).

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out.
    stats : ndarray (3,) int64
        [steps, torque-free evaluations (after merging), torque evaluations].
    """
    n_out = t_out.shape[0]
    n_kicks = kick_coeffs.shape[0]
    big_a, big_b, big_c = model[BODY_A], model[BODY_B], model[BODY_C]
    ys = np.empty((n_out, STATE_SIZE))
    stats = np.zeros(3, dtype=np.int64)
    q = y0[0:4].copy()
    m = np.empty(3)
    scratch = np.empty(DRIFT_SCRATCH_SIZE)
    m[0], m[1], m[2] = big_a * y0[4], big_b * y0[5], big_c * y0[6]
    # Time of kick i within a step, in units of τ: the drifts before it.
    kick_offsets = np.empty(n_kicks)
    acc = 0.0
    for i in range(n_kicks):
        acc += drift_coeffs[i]
        kick_offsets[i] = acc
    has_perturbers = model[MODEL_PERTURBERS] > 0.0
    t_start = t0
    for k in range(n_out):
        span = t_out[k] - t_start
        n_steps = max(1, int(math.ceil(abs(span) / step - STEP_COUNT_SLACK)))
        tau = span / n_steps
        pending = 0.0  # drift time not yet applied (merged across kicks with zero weight and steps)
        for s in range(n_steps):
            pending += drift_coeffs[0] * tau
            for i in range(n_kicks):
                if pending != 0.0:
                    drift(pending, q, m, big_a, big_b, big_c, short_setup, scratch)
                    stats[STAT_DRIFTS] += 1
                    pending = 0.0
                if has_perturbers:
                    # times from the interval start, not accumulated: no rounding drift of t
                    kick(t_start + (s + kick_offsets[i]) * tau, kick_coeffs[i] * tau, q, m, model)
                    stats[STAT_KICKS] += 1
                pending += drift_coeffs[i + 1] * tau
        if pending != 0.0:
            drift(pending, q, m, big_a, big_b, big_c, short_setup, scratch)
            stats[STAT_DRIFTS] += 1
        stats[STAT_STEPS] += n_steps
        t_start = t_out[k]
        for i in range(4):
            ys[k, i] = q[i]
        ys[k, 4], ys[k, 5], ys[k, 6] = m[0] / big_a, m[1] / big_b, m[2] / big_c
    return ys, stats


# ---------------------------------------------------------------------------------------------
# Python front end: validation only, then one call into the kernel.


def integrate_splitting(y0, t0, t_out, model, step, scheme="saba2", free_flow_setup="short",
                        return_stats=False):
    """Integrate the rotational equations with a fixed-step symplectic splitting (free flow + kicks).

    Parameters
    ----------
    y0 : array_like (7,)
        Initial state (q0, q1, q2, q3, ωx, ωy, ωz): scalar-first quaternion body → inertial
        (normalised here) and body angular velocity (rad per time unit) on the principal axes.
    t0 : float
        Initial time (time unit of the model, e.g. days).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0 (backward integration allowed: both flows are
        exact in either direction).
    model : ndarray
        From :func:`spinorbit.core.dynamics.make_model`, principal moments A ≤ B ≤ C.
    step : float
        Largest step (time unit, > 0). Every output interval is divided into the smallest number of
        equal steps not longer than ``step``, so the run lands on each output time.
    scheme : str
        One of :data:`SCHEMES`: ``"strang"``, ``"yoshida4"``, ``"saba2"`` (default), ``"saba3"``,
        ``"sbab2"`` (module docstring; Laskar & Robutel 2001, Yoshida 1990).
    free_flow_setup : str
        ``"short"`` (default): each drift is set up in double precision without the node frame
        (:func:`relative_flow_constants`; the whole step measured 1.9× cheaper); ``"long"``: with
        the double-double setup of
        :func:`.torque_free.flow_constants` built for long spans (no accuracy gain for short drifts;
        kept for comparison, ``docs/splitting.md``).
    return_stats : bool
        Also return a dict ``steps``, ``drifts`` (torque-free evaluations), ``kicks`` (torque
        evaluations).

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out (q unit norm).
    stats : dict, optional

    Raises
    ------
    ValueError
        Bad state, times, step, scheme or model (moments not ordered A ≤ B ≤ C, or output times
        outside the span of a sampled perturber).

    References
    ----------
    Touma & Wisdom 1994, AJ 107, 1189; Celledoni et al. 2008, SIAM J. Sci. Comput. 30, 2084;
    Laskar & Robutel 2001, Celest. Mech. Dyn. Astron. 80, 39; Yoshida 1990, Phys. Lett. A 150, 262.
    """
    y0 = validate_state(y0)
    t0 = float(t0)
    t_out = _validate_times(t0, t_out)
    try:
        step = float(step)
    except (TypeError, ValueError):
        raise ValueError(f"step: expected a positive number (time unit of the model), got {step!r}.") from None
    if not (math.isfinite(step) and step > 0.0):
        raise ValueError(
            f"step: expected a finite step > 0 (time unit of the model), got {step!r}; "
            "try a small fraction (e.g. 1/20) of the rotation period."
        )
    if scheme not in SCHEMES:
        raise ValueError(f"scheme: expected one of {sorted(SCHEMES)}, got {scheme!r}.")
    model = np.ascontiguousarray(model, dtype=float)
    big_a, big_b, big_c = model[BODY_A], model[BODY_B], model[BODY_C]
    if not (0.0 < big_a <= big_b <= big_c):
        raise ValueError(
            f"model: expected principal moments 0 < A ≤ B ≤ C (the torque-free flow works on ordered "
            f"principal axes), got ({big_a!r}, {big_b!r}, {big_c!r}); reorder the body axes "
            "(docs/conventions.md) and rotate y0 accordingly."
        )
    lo, hi = sampled_span(model, MODEL_PERTURBERS)
    t_min, t_max = min(t0, t_out.min()), max(t0, t_out.max())
    if t_min < lo or t_max > hi:
        raise ValueError(
            f"t_out: the run spans [{t_min!r}, {t_max!r}] but sampled perturbers are defined only on "
            f"[{lo!r}, {hi!r}]; extend the samples or shorten the run."
        )
    if free_flow_setup not in ("short", "long"):
        raise ValueError(f"free_flow_setup: expected 'short' or 'long', got {free_flow_setup!r}.")
    c, d = SCHEMES[scheme]
    ys, stats = integrate_splitting_kernel(y0, t0, t_out, model, step, np.array(c, dtype=float),
                                           np.array(d, dtype=float), free_flow_setup == "short")
    if return_stats:
        return ys, {"steps": int(stats[STAT_STEPS]), "drifts": int(stats[STAT_DRIFTS]),
                    "kicks": int(stats[STAT_KICKS])}
    return ys
