"""The set-up of the exact torque-free flow: the constants of one motion, formed once per state.

Everything :func:`.flow.evaluate_flow` needs at each time is computed here from the exact double
inputs (attitude, body momentum, moments A ≤ B ≤ C) and stored in one float array in the ``FL_*``
layout below: the mode and flip, the node frame R1(I) R3(h), and the secular quantities of eq. (12)
in double-double (the argument rate ν, the half period 2K, the rate c G of g, the advance 2κΠ of g
per half period, κ, and g0 − κ pn(arg0)). Why double-double, and the formulas: the module docstring
of :mod:`.flow` and ``docs/torque_free.md``.

The set-up is written in three parts so that its middle can run for eight states at once
(:mod:`.flow_blocks`): :func:`set_up_start` (motion constants, the phase constants of
:mod:`.phase_constants`, the kind of motion), :func:`integrals_of_state` (the two R_F and the AGM
of :mod:`spinorbit.core.math.complete_agm`), :func:`set_up_finish` (everything after them).
"""

import math

import numpy as np

from spinorbit.core.elements.canonical import (
    MO_MODE,
    MO_PARAM_C,
    MO_SIZE,
    MODE_SAM,
    MODE_UNIFORM,
    amplitude_from_momentum,
    elliptic_constants,
    flip_signs,
    motion_from_momentum_into,
)
from spinorbit.core.free_motion.node_frame import node_of_state
from spinorbit.core.free_motion.phase_constants import moment_constants, phase_constants_dd
from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.carlson import rf, rf_pair
from spinorbit.core.math.complete_agm import complete_k_pi_dd
from spinorbit.core.math.ddouble import (
    dd_add,
    dd_div,
    dd_mul,
    dd_remainder_dd,
    dd_scale,
    dd_sqrt,
)
from spinorbit.core.math.elliptic_integrals import (
    METHOD_LARGE_NEGATIVE,
    NK_METHOD,
    NK_N,
    characteristic_constants_with_complete,
    ellipf_k,
    pi_principal,
    pn_k,
)
from spinorbit.core.math.elliptic_periods import (
    MK_K_HI,
    MK_K_LO,
    MK_M,
    MK_MC,
    MK_SQRT_MUC,
    parameter_constants_with_k,
)
from spinorbit.core.math.jacobi import sncndn_reduced
from spinorbit.core.math.pn_fourier import (
    FOURIER_MAX_TERMS,
    pn_fourier_coefficients_at,
    pole_integral,
    sine_series,
)

# Indices into the per-state flow constants (see flow_constants). The MO_* motion constants, the
# elliptic constants and these describe one torque-free motion completely.
(
    FL_MODE,  # MODE_SAM / MODE_LAM / MODE_UNIFORM (separatrix: MODE_SAM with FL_PERIODIC == 0)
    FL_PERIODIC,  # 1 if the argument is reduced by the double-double half period 2K, 0 at m = 1
    FL_RATE_HI,  # ν = d(arg)/dt (uniform rotation: |ω|/2, the rate of the half angle)
    FL_RATE_LO,
    FL_ARG0,  # arg at t = 0 (a double: its rounding is a constant offset, not a drift)
    FL_PERIOD_HI,  # 2K(p), the half period of the argument
    FL_PERIOD_LO,
    FL_G_RATE_HI,  # c G, secular rate of g (rad per time unit)
    FL_G_RATE_LO,
    FL_G_ADVANCE_HI,  # 2 κ Π(n|p): advance of g per half period of the argument, beyond c G t
    FL_G_ADVANCE_LO,
    FL_G_CONST_HI,  # g0 − κ pn(arg0)
    FL_G_CONST_LO,
    FL_QN_W,  # quaternion of the node frame (R1(I) R3(h))ᵀ; uniform rotation: the initial attitude
    FL_QN_X,
    FL_QN_Y,
    FL_QN_Z,
    FL_AXIS_X,  # uniform rotation: unit spin axis ω/|ω| in the body frame
    FL_AXIS_Y,
    FL_AXIS_Z,
    FL_FLIP_X,  # diagonal of the body-frame flip
    FL_FLIP_Y,
    FL_FLIP_Z,
    FL_FLIP,  # FLIP_* code
    FL_M0_X,  # body momentum at t = 0 (constant in a uniform rotation)
    FL_M0_Y,
    FL_M0_Z,
    FL_KAPPA_HI,  # κ = (a−c) G / ν, the coefficient of pn in g (rad per unit of pn)
    FL_KAPPA_LO,
    FL_FOURIER_TERMS,  # N > 0: κ pn(r) from the nome series of .pn_fourier; 0: the Carlson form
    FL_FOURIER_SCALE,  # π / K: θ = π r / K
    FL_LINEAR_HI,  # κ Π / K = W / (2K): the secular slope of κ pn(r) in r
    FL_LINEAR_LO,
    FL_FOURIER_0,  # κ c_1 … κ c_N (FOURIER_MAX_TERMS slots)
) = range(34)
FLOW_SIZE = FL_FOURIER_0 + FOURIER_MAX_TERMS


# --------------------------------------------------------------------------------------------------
# Double-double constants of one motion
# --------------------------------------------------------------------------------------------------


@jit
def flow_constants(quaternion, momentum, big_a, big_b, big_c):
    """Everything the per-time evaluation needs for one state (computed once per state).

    Parameters
    ----------
    quaternion : (4,) ndarray
        Attitude at t = 0, scalar first, body → inertial (unit norm).
    momentum : (3,) ndarray
        Body angular momentum at t = 0 (principal axes A ≤ B ≤ C; any consistent unit).
    big_a, big_b, big_c : float
        Principal moments A ≤ B ≤ C (same mass·length² unit as implied by the momentum).

    Returns
    -------
    flow : (FLOW_SIZE,) ndarray
        The ``FL_*`` constants.
    mo, mk, pk : tuples
        Motion constants (:func:`.canonical.motion_constants`), parameter and pn constants of the
        elliptic kernels.
    """
    flow = np.empty(FLOW_SIZE)
    mo, mk, pk = flow_constants_into(flow, quaternion, momentum, big_a, big_b, big_c)
    return flow, mo, mk, pk


@jit
def flow_constants_into(flow, quaternion, momentum, big_a, big_b, big_c):
    """:func:`flow_constants` into a caller's (FLOW_SIZE,) array; returns (mo, mk, pk).

    For loops over many states (:func:`.flow.propagate_many_into`): one buffer for all of them
    instead of an allocation per state. Every slot the evaluation reads is written.
    """
    ic, inertia_dd = moment_constants(big_a, big_b, big_c)
    return flow_constants_shared(flow, quaternion, momentum, big_a, big_b, big_c, ic, inertia_dd)


@jit
def flow_constants_shared(flow, quaternion, momentum, big_a, big_b, big_c, ic, inertia_dd):
    """:func:`flow_constants_into` with the body's :func:`moment_constants` (ic, inertia_dd) given.

    States of one body share them; they were ≈ 12 divisions of every state's set-up.
    """
    mo = np.empty(MO_SIZE)
    mk, pk = flow_constants_buffers(flow, mo, quaternion, momentum, big_a, big_b, big_c, ic, inertia_dd)
    return mo, mk, pk


@jit(inline=INLINE)
def flow_constants_buffers(flow, mo, quaternion, momentum, big_a, big_b, big_c, ic, inertia_dd):
    """:func:`flow_constants_shared` into a caller's (MO_SIZE,) motion-constants array too; returns
    (mk, pk). One buffer for a loop's states: the allocation cost ≈ 20 ns of each set-up.

    The set-up in three parts: :func:`set_up_start` up to the two R_F and the AGM, the integrals
    (:func:`integrals_of_state`), :func:`set_up_finish` after them. :mod:`.flow_blocks` runs the
    middle part for eight states at once between the same two ends.
    """
    staged = set_up_start(flow, mo, quaternion, momentum, big_a, big_b, big_c, ic, inertia_dd)
    if staged[ST_KIND] == KIND_UNIFORM:
        return elliptic_constants(mo)  # unused by a uniform rotation; returned for one signature
    g0, qn = node_of_state(quaternion, momentum[0], momentum[1], momentum[2], flow[FL_FLIP_X], flow[FL_FLIP_Y],
                           flow[FL_FLIP_Z], staged[ST_MX], staged[ST_MY])
    return set_up_finish(flow, mo, ic, staged, integrals_of_state(staged), g0, qn)


# What set_up_start hands to the integrals and to set_up_finish (a tuple of floats, so that
# .flow_blocks can keep eight of them in an array across the integrals of all eight).
(
    ST_KIND,  # KIND_* below
    ST_MX,  # working-frame momentum (the flip applied)
    ST_MY,
    ST_MZ,
    ST_F_HI,  # f = −n and p_c as double-doubles, p as a double (phase_constants_dd)
    ST_F_LO,
    ST_PC_HI,
    ST_PC_LO,
    ST_PARAM,
    ST_AMPLITUDE_J,  # the amplitude at t = 0: whole turns of π, sin and cos of the rest
    ST_AMPLITUDE_SIN,
    ST_AMPLITUDE_COS,
    ST_POLE_PREFACTOR,  # the pole of pn's integrand: prefactor · R_F(x, y, z), and which form
    ST_POLE_X,
    ST_POLE_Y,
    ST_POLE_Z,
    ST_POLE_NEAR,
) = range(17)
STAGE_SIZE = 17
# KIND_PERIODIC needs both R_F and the AGM; KIND_AGM_ONLY (p_c > 0 in double-double but the motion's
# rounded p_c is 0) only the AGM; KIND_SEPARATRIX neither; KIND_UNIFORM is complete after the start.
KIND_UNIFORM, KIND_PERIODIC, KIND_AGM_ONLY, KIND_SEPARATRIX = 0.0, 1.0, 2.0, 3.0
# The integrals' results: (R_F of the amplitude, R_F of the pole, K_hi, K_lo, Π_hi, Π_lo)
INTEGRALS_SIZE = 6


@jit(inline=INLINE)
def set_up_start(flow, mo, quaternion, momentum, big_a, big_b, big_c, ic, inertia_dd):
    """The set-up up to its integrals: the flow slots known before them, and the ``ST_*`` tuple.

    :func:`set_up_motion`, the phase constants (:func:`.phase_constants.phase_constants_dd`), then
    :func:`set_up_phase`; :mod:`.flow_blocks` forms the phase constants of eight states at once between them.
    """
    mode, mx, my, mz = set_up_motion(flow, mo, quaternion, momentum, big_a, big_b, big_c, ic)
    if mode == MODE_UNIFORM:
        return UNIFORM_STAGE
    phase = phase_constants_dd(mode, mx, my, mz, inertia_dd)
    return set_up_phase(flow, mo, mode, mx, my, mz, phase, ic)


# set_up_start's tuple for a uniform rotation: its flow constants are complete
UNIFORM_STAGE = (KIND_UNIFORM, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@jit(inline=INLINE)
def set_up_motion(flow, mo, quaternion, momentum, big_a, big_b, big_c, ic):
    """Mode, flip and motion constants into flow and mo (a uniform rotation's constants complete);
    returns (mode, working-frame M_x, M_y, M_z)."""
    flip = motion_from_momentum_into(mo, momentum[0], momentum[1], momentum[2], ic)
    return motion_into_flow(flow, mo, quaternion, momentum, flip, big_a, big_b, big_c)


@jit(inline=INLINE)
def motion_into_flow(flow, mo, quaternion, momentum, flip, big_a, big_b, big_c):
    """:func:`set_up_motion` after the motion constants ``mo`` and the flip are known."""
    m0x, m0y, m0z = momentum[0], momentum[1], momentum[2]
    flow[:] = 0.0
    mode = int(mo[MO_MODE])
    flow[FL_MODE] = mode
    flow[FL_FLIP] = flip
    fx, fy, fz = flip_signs(flip)
    flow[FL_FLIP_X], flow[FL_FLIP_Y], flow[FL_FLIP_Z] = fx, fy, fz
    flow[FL_M0_X], flow[FL_M0_Y], flow[FL_M0_Z] = m0x, m0y, m0z
    if mode == MODE_UNIFORM:
        _uniform_rotation_constants(flow, quaternion, m0x, m0y, m0z, big_a, big_b, big_c)
    return mode, fx * m0x, fy * m0y, fz * m0z


@jit(inline=INLINE)
def set_up_phase(flow, mo, mode, mx, my, mz, phase, ic):
    """The phase constants (:func:`.phase_constants.phase_constants_dd`'s tuple) into flow, the kind of
    the motion, and what its integrals need: the ``ST_*`` tuple of :func:`set_up_start`."""
    nuh, nul, cgh, cgl, kah, kal, fh, fl, pch, pcl, param = phase
    flow[FL_RATE_HI], flow[FL_RATE_LO] = nuh, nul
    flow[FL_G_RATE_HI], flow[FL_G_RATE_LO] = cgh, cgl
    flow[FL_KAPPA_HI], flow[FL_KAPPA_LO] = kah, kal
    if not pch > 0.0:
        return (KIND_SEPARATRIX, mx, my, mz, fh, fl, pch, pcl, param, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    if not mo[MO_PARAM_C] > 0.0:  # p_c > 0 in double-double: the period, even where p_c rounds to 0
        return (KIND_AGM_ONLY, mx, my, mz, fh, fl, pch, pcl, param, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    # The two R_F of the set-up need no K: the amplitude's F (the start of the argument) and the
    # distance of pn's pole (the nome series). They run as one pair, issued before the AGM, so their
    # latencies overlap instead of adding up.
    j0_am, s_am, c_am = _amplitude_of_momentum(mx, my, mz, mode, ic)
    pre, x, y, z, near = pole_integral(fh, param)
    return (KIND_PERIODIC, mx, my, mz, fh, fl, pch, pcl, param, j0_am, s_am, c_am, pre, x, y, z,
            1.0 if near else 0.0)


@jit(inline=INLINE)
def integrals_of_state(staged):
    """(R_F of the amplitude, R_F of the pole, K_hi, K_lo, Π_hi, Π_lo) of one state, where its kind needs them."""
    rf_am, rf_pole, kh, kl, pih, pil = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    kind = staged[ST_KIND]
    if kind == KIND_PERIODIC:
        c, s = staged[ST_AMPLITUDE_COS], staged[ST_AMPLITUDE_SIN]
        rf_am, rf_pole = rf_pair(c * c, c * c + staged[ST_PC_HI] * (s * s), 1.0,
                                 staged[ST_POLE_X], staged[ST_POLE_Y], staged[ST_POLE_Z])
    if kind == KIND_PERIODIC or kind == KIND_AGM_ONLY:
        kh, kl, pih, pil = complete_k_pi_dd(staged[ST_F_HI], staged[ST_F_LO], staged[ST_PC_HI], staged[ST_PC_LO])
    return rf_am, rf_pole, kh, kl, pih, pil


@jit(inline=INLINE)
def _uniform_rotation_constants(flow, quaternion, m0x, m0y, m0z, big_a, big_b, big_c):
    """Permanent rotation: ω = I⁻¹M ∥ M, q(t) = q0 ⊗ (cos(|ω|t/2), k sin(|ω|t/2)), k = ω/|ω|, with
    |ω|/2 in double-double, so the half angle does not drift either."""
    oxh, oxl = dd_div(m0x, 0.0, big_a, 0.0)
    oyh, oyl = dd_div(m0y, 0.0, big_b, 0.0)
    ozh, ozl = dd_div(m0z, 0.0, big_c, 0.0)
    xxh, xxl = dd_mul(oxh, oxl, oxh, oxl)
    yyh, yyl = dd_mul(oyh, oyl, oyh, oyl)
    zzh, zzl = dd_mul(ozh, ozl, ozh, ozl)
    sqh, sql = dd_add(xxh, xxl, yyh, yyl)
    sqh, sql = dd_add(sqh, sql, zzh, zzl)
    rh, rl = dd_sqrt(sqh, sql)
    flow[FL_RATE_HI], flow[FL_RATE_LO] = 0.5 * rh, 0.5 * rl
    if rh > 0.0:
        flow[FL_AXIS_X], flow[FL_AXIS_Y], flow[FL_AXIS_Z] = oxh / rh, oyh / rh, ozh / rh
    flow[FL_QN_W], flow[FL_QN_X] = quaternion[0], quaternion[1]
    flow[FL_QN_Y], flow[FL_QN_Z] = quaternion[2], quaternion[3]


@jit(inline=INLINE)
def set_up_finish(flow, mo, ic, staged, integrals, g0, qn):
    """The set-up after its integrals (``integrals``: :func:`integrals_of_state`'s tuple) and the node
    frame (g0 and the node quaternion ``qn``: :func:`.node_frame.node_of_state`); returns (mk, pk)."""
    kind = staged[ST_KIND]
    mx, my, mz = staged[ST_MX], staged[ST_MY], staged[ST_MZ]
    fh, pch, param = staged[ST_F_HI], staged[ST_PC_HI], staged[ST_PARAM]
    kah, kal = flow[FL_KAPPA_HI], flow[FL_KAPPA_LO]
    rf_am, rf_pole, kh, kl, pih, pil = integrals
    periodic = kind == KIND_PERIODIC
    perh, perl, wh, wl = math.inf, 0.0, 0.0, 0.0
    if periodic or kind == KIND_AGM_ONLY:
        perh, perl = 2.0 * kh, 2.0 * kl
        wh, wl = dd_mul(kah, kal, 2.0 * pih, 2.0 * pil)
    if periodic:
        # kernel constants from the once-rounded double-double p, p_c, n (not from ratios of rounded
        # differences: near the separatrix those lose ε/p_c in p_c), with K and Π from the
        # compensated AGM above instead of a second AGM and a Carlson R_J per state
        mk = parameter_constants_with_k(param, pch, kh, kl)
        pk = characteristic_constants_with_complete(-fh, param, pih + pil)
        arg0 = _argument_from_amplitude(staged[ST_AMPLITUDE_J], staged[ST_AMPLITUDE_SIN], rf_am, kh, kl)
    else:  # the separatrix: the kernels' closed forms, from the motion constants
        mk, pk = elliptic_constants(mo)
        # m_c = 0: F = atanh(sin am) in Carlson's form, ±inf past ±π/2 (ellipf_k's cases)
        arg0 = ellipf_k(amplitude_from_momentum(mx, my, mz, mo, ic), mk)
    flow[FL_QN_W], flow[FL_QN_X], flow[FL_QN_Y], flow[FL_QN_Z] = qn
    flow[FL_ARG0] = arg0
    flow[FL_PERIODIC] = 1.0 if periodic else 0.0
    flow[FL_PERIOD_HI], flow[FL_PERIOD_LO] = perh, perl
    flow[FL_G_ADVANCE_HI], flow[FL_G_ADVANCE_LO] = wh, wl
    if periodic:
        _fourier_constants(flow, mk, pk, staged[ST_POLE_PREFACTOR] * rf_pole, staged[ST_POLE_NEAR] > 0.0)
    # g0 − κ pn(arg0), with pn(arg0) = 2Π j0 + pn(r0) split as at every later time, so that the
    # large parts cancel exactly at t = 0 (κ pn is huge for nearly symmetric bodies)
    if periodic:
        j0, r0h, r0l = dd_remainder_dd(arg0, 0.0, perh, perl)
        s, c, d = 0.0, 0.0, 0.0  # the nome series needs no sn, cn, dn (≈ 50 ns of the set-up)
        if flow[FL_FOURIER_TERMS] == 0.0:
            s, c, d = sncndn_reduced(r0h, mk[MK_M], mk[MK_MC], mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO])
        ph, pl = flow_kappa_pn(flow, r0h, r0l, s, c, d, pk)
        jwh, jwl = dd_scale(wh, wl, j0)
        ph, pl = dd_add(ph, pl, jwh, jwl)
    else:
        ph, pl = dd_mul(kah, kal, pn_k(arg0, mk, pk), 0.0)
    ch, cl = dd_add(g0, 0.0, -ph, -pl)
    flow[FL_G_CONST_HI], flow[FL_G_CONST_LO] = ch, cl
    return mk, pk


@jit
def _argument_of_momentum(mx, my, mz, mode, ic, mk):
    """The elliptic argument F(am | p) at the working-frame momentum (u in SAM, v in LAM), 0 ≤ p < 1.

    :func:`.canonical.amplitude_from_momentum` followed by :func:`.elliptic_integrals.ellipf_k`,
    without the atan2 and the sin, cos of its result (:func:`_amplitude_of_momentum`):
    F = 2jK + sin r · R_F(cos² r, cos² r + p_c sin² r, 1) (DLMF 19.25.5, 19.25.14). The set-up forms the same
    sum with this R_F paired with another (:func:`flow_constants_buffers`).
    """
    j, s, c = _amplitude_of_momentum(mx, my, mz, mode, ic)
    return _argument_from_amplitude(j, s, rf(c * c, c * c + mk[MK_MC] * (s * s), 1.0), mk[MK_K_HI], mk[MK_K_LO])


@jit(inline=INLINE)
def _argument_from_amplitude(j, sin_r, rf_r, k_hi, k_lo):
    """F = 2jK + sin r · R_F(cos² r, cos² r + p_c sin² r, 1), K = k_hi + k_lo: the small terms summed first."""
    return 2.0 * j * k_hi + (2.0 * j * k_lo + sin_r * rf_r)


@jit
def _amplitude_of_momentum(mx, my, mz, mode, ic):
    """(j, sin r, cos r) of the amplitude am = jπ + r, |r| ≤ π/2, at the working-frame momentum.

    sin and cos of the amplitude are the momentum's own ratios (the atan2 of
    :func:`.canonical.amplitude_from_momentum`), and the whole turns of π (|am| ≤ π, so
    j ∈ {−1, 0, 1}) follow from their signs. At M = 0 along both axes, (0, 0, 1): atan2(0, 0) = 0
    (spin exactly about C in SAM).
    """
    _a, _b, _c, a_b, b_c, a_c = ic
    if mode == MODE_SAM:
        ys, xs = math.sqrt(b_c) * my, math.sqrt(a_c) * mx
    else:
        ys, xs = math.sqrt(a_b) * my, math.sqrt(a_c) * mz
    norm2 = ys * ys + xs * xs  # not hypot (≈ 15 ns): momenta below 1e150 cannot overflow it
    if not norm2 > 0.0:
        return 0.0, 0.0, 1.0
    inv = 1.0 / math.sqrt(norm2)
    s, c = ys * inv, xs * inv
    j = 0.0
    if c < 0.0:  # am beyond ±π/2: r = am − jπ, sin r = −s, cos r = −c
        j = math.copysign(1.0, s)
        s, c = -s, -c
    return j, s, c


@jit
def kappa_pn(kah, kal, rh, rl, s, c, d, pk):
    """κ · pn(r) as a double-double for |r| ≤ K, from sn, cn, dn of r and r as a double-double.

    Carlson form (|n| < 1): pn(r) = r + (n/3) s³ R_J (F(am r) = r), and κ r is formed in
    double-double: for nearly symmetric bodies (A ≈ B) κ is large while pn(r) ≈ r, and κ · pn(r)
    rounded as a whole would cost ε·κ·r rad. R_C form (n ≤ −1): pn(r) is far from r (≈ r/(1 − n)),
    so splitting r off would cancel; κ · pn(r) is formed from the whole value.

    Parameters
    ----------
    kah, kal : float
        κ = (a − c) G / ν (``FL_KAPPA_*``) as a double-double, rad per unit of pn.
    rh, rl : float
        The reduced argument r (dimensionless, |r| ≤ K) as a double-double.
    s, c, d : float
        sn, cn, dn of r (:func:`spinorbit.core.math.jacobi.sncndn_reduced`).
    pk : tuple
        :func:`spinorbit.core.math.elliptic_integrals.pn_constants` of the motion.

    Returns
    -------
    hi, lo : float
        κ · pn(r) (rad), the r-dependent part of g in paper eqs. (8) and (12).
    """
    if pk[NK_METHOD] == METHOD_LARGE_NEGATIVE:
        return dd_mul(kah, kal, pi_principal(s, c * c, d * d, rh, pk), 0.0)
    xh, xl = dd_add(rh, rl, pi_principal(s, c * c, d * d, 0.0, pk), 0.0)
    return dd_mul(kah, kal, xh, xl)


@jit(inline=INLINE)
def _fourier_constants(flow, mk, pk, distance, near):
    """Fill the FL_FOURIER_* / FL_LINEAR_* slots when the nome series of pn converges fast enough.

    ``distance``, ``near``: the pole of pn's integrand (:func:`.pn_fourier.pole_integral`, its R_F
    formed by the caller).

    The slope κΠ/K = W/(2K) is formed in double-double from the double-double W and 2K; the
    normalisation of the series is in closed form (:mod:`.pn_fourier`), so it needs no 1 − Π/K,
    which cancels when Π ≈ K (n → 0).
    """
    lh, ll = dd_div(flow[FL_G_ADVANCE_HI], flow[FL_G_ADVANCE_LO], flow[FL_PERIOD_HI], flow[FL_PERIOD_LO])
    k_quarter = mk[MK_K_HI]
    terms = pn_fourier_coefficients_at(-pk[NK_N], mk[MK_M], k_quarter, flow[FL_KAPPA_HI], distance, near,
                                       flow[FL_FOURIER_0:])
    flow[FL_FOURIER_TERMS] = terms
    flow[FL_FOURIER_SCALE] = math.pi / k_quarter
    flow[FL_LINEAR_HI], flow[FL_LINEAR_LO] = lh, ll


@jit(inline=INLINE)
def flow_kappa_pn(flow, rh, rl, s, c, d, pk):
    """κ · pn(r) for |r| ≤ K as a double-double, by whichever form the set-up chose.

    FL_FOURIER_TERMS > 0: (κΠ/K) · r in double-double plus κ Σ c_k sin(kπr/K) (:mod:`.pn_fourier`);
    otherwise the Carlson form :func:`kappa_pn`. The set-up forms g0 − κ pn(arg0) with this same
    function, so the two agree exactly at t = 0.
    """
    terms = int(flow[FL_FOURIER_TERMS])
    if terms > 0:
        xh, xl = dd_mul(flow[FL_LINEAR_HI], flow[FL_LINEAR_LO], rh, rl)
        periodic = sine_series(flow[FL_FOURIER_SCALE] * rh, flow, FL_FOURIER_0, terms)
        return dd_add(xh, xl, periodic, 0.0)
    return kappa_pn(flow[FL_KAPPA_HI], flow[FL_KAPPA_LO], rh, rl, s, c, d, pk)
