"""The exact torque-free motion (paper eq. 12) over long spans: S, Z, H, z, h constant, s = s0 + a S t.

What is evaluated
-----------------
With the working frame of :mod:`.canonical` (principal axes A ≤ B ≤ C, the sense carried by a π flip),
the elliptic argument (u in SAM, v in LAM) and the Andoyer angle g are, from eqs. (7), (8) and (12),

    arg(t) = arg0 + ν t,
    g(t)   = g0 + c G t + κ · (pn(arg(t)) − pn(arg0)),

with the argument rate ν = d(arg)/dt (ν = u/s · a S), c G the secular rate of g and κ (``MO_PN_COEFF``):

    SAM  ν = √(((a−b) M_y² + (a−c) M_z²)(b−c)),   LAM  ν = √(((a−c) M_x² + (b−c) M_y²)(a−b)),
    κ = (a − c) G / ν  (both modes),

where a − b = (B − A)/(AB) etc. and M is the working-frame body momentum. S, Z, H, z, h, and hence the
node frame R1(I) R3(h), never change.

Long spans: the phase as (whole half periods, reduced remainder)
----------------------------------------------------------------
Rounding ν, c G and the per-period advance of pn to doubles makes the phase drift by ≈ ε·ν·t: the
attitude error of a double-precision evaluation grows linearly, 4e-11 rad after 1e5 time units for
the Hairer–Lubich–Wanner body. Here every secular quantity is formed in double-double from the exact
double inputs (A, B, C, M):

* ν, c G, κ from error-free products of the inputs (:mod:`.ddouble`);
* the half period 2K(p) of the argument and the complete Π(n | p) (n = ``MO_PN_N`` ≤ 0, p < 1 the
  parameter actually used by the kernels: m in SAM, μ = 1/m in LAM) from one compensated AGM
  (DLMF 19.8.5 and 19.8.6–8), with the parameter and the characteristic themselves formed in
  double-double, so K and Π belong to the exact inputs and not to their rounded ratios;
* arg(t) = j · 2K + r with j = rint(arg/2K) and |r| ≤ K, both from the double-double arg; pn advances
  by 2Π per half period, so g(t) = [g0 − κ pn(arg0) + c G t + 2κΠ j] + κ pn(r): the bracket is
  a double-double; κ pn(r) joins it in double-double (with κ r formed exactly where pn(r) ≈ r: for
  nearly symmetric bodies κ is huge), and the sum is reduced modulo 4π (half angles feed the
  quaternion).

The reduced r then goes to the double kernels (one sn/cn/dn, and the pn of r: its nome sine series
of :mod:`spinorbit.core.math.pn_fourier` where that converges fast, else one Π of the principal
range), whose errors are bounded and do not grow. Measured errors are in ``docs/torque_free.md``.

Bodies with two exactly equal moments (and spheres) do not come here: the loops below send them to
the regular precession in closed form (:mod:`.regular_precession`, trig only, the same double-double
phase treatment), unless ``closed_forms=False``.

Where it lives: the constants of one motion are set up once per state by
:func:`.flow_constants.flow_constants` (module :mod:`.flow_constants`, which owns the ``FL_*``
layout; eight states of one body at once: :mod:`.flow_blocks`); this module evaluates them at each
time (:func:`evaluate_flow`) and runs the loops over states and times.

Output convention: quaternions scalar first, body → inertial (``docs/conventions.md``), and body
angular momenta, in the user's principal-axis body frame.
"""

import math

import numpy as np

from spinorbit.core.elements.canonical import (
    FLIP_A,
    FLIP_B,
    FLIP_C,
    MO_G,
    MO_SIZE,
    MODE_UNIFORM,
    body_from_sncndn,
)
from spinorbit.core.errors import require_finite, require_finite_result
from spinorbit.core.free_motion.flow_constants import (
    FL_ARG0,
    FL_AXIS_X,
    FL_AXIS_Y,
    FL_AXIS_Z,
    FL_FLIP,
    FL_FLIP_X,
    FL_FLIP_Y,
    FL_FLIP_Z,
    FL_G_ADVANCE_HI,
    FL_G_ADVANCE_LO,
    FL_G_CONST_HI,
    FL_G_CONST_LO,
    FL_G_RATE_HI,
    FL_G_RATE_LO,
    FL_KAPPA_HI,
    FL_KAPPA_LO,
    FL_M0_X,
    FL_M0_Y,
    FL_M0_Z,
    FL_MODE,
    FL_PERIOD_HI,
    FL_PERIOD_LO,
    FL_PERIODIC,
    FL_QN_W,
    FL_QN_X,
    FL_QN_Y,
    FL_QN_Z,
    FL_RATE_HI,
    FL_RATE_LO,
    FLOW_SIZE,
    flow_constants,
    flow_constants_buffers,
    flow_kappa_pn,
)
from spinorbit.core.free_motion.flow_blocks import (
    BLOCK,
    INTEGRALS_SIZE,
    MOTION_SIZE,
    NODE_SIZE,
    STAGE_SIZE,
    finish_lane,
    integrals_of_block,
    nodes_of_block,
    set_up_block_start,
)
from spinorbit.core.free_motion.node_frame import half_angles
from spinorbit.core.free_motion.phase_constants import moment_constants
from spinorbit.core.free_motion.regular_precession import (
    NO_SYMMETRY_AXIS,
    evaluate_precession,
    precession_constants,
    symmetry_axis,
)
from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.ddouble import (
    TWO_PI_HI,
    TWO_PI_LO,
    dd_add,
    dd_mul,
    dd_remainder,
    dd_remainder_dd,
    dd_scale,
    parity,
)
from spinorbit.core.math.elliptic_integrals import pn_k
from spinorbit.core.math.elliptic_periods import (
    MK_K_HI,
    MK_K_LO,
    MK_M,
    MK_MC,
    MK_SQRT_MUC,
)
from spinorbit.core.math.jacobi import sncndn_k, sncndn_reduced
from spinorbit.core.math.rotations import attitude_to_quat, qmul_parts, quat_to_attitude

# The FL_* layout and the set-up are exported by their home, .flow_constants (one path per name).
__all__ = [
    "evaluate_flow", "evaluate_into", "flow_state", "propagate_many_into", "propagate_state_into",
    "propagate_states_into", "torque_free_attitudes", "torque_free_states", "torque_free_states_many",
    "uniform_rotation",
]


@jit
def _reduced_half(xh, xl):
    """(x/2) reduced modulo 2π, from a double-double x (the half angle of a quaternion)."""
    _, r = dd_remainder(0.5 * xh, 0.5 * xl, TWO_PI_HI, TWO_PI_LO)
    return r


@jit
def evaluate_flow(t, flow, mo, mk, pk, q_out, m_out):
    """Attitude quaternion and body momentum at time t of the motion described by flow constants.

    Writes q_out[0:4] (scalar first, body → inertial) and m_out[0:3] (body momentum): the values of
    :func:`flow_state`.
    """
    q_out[0], q_out[1], q_out[2], q_out[3], m_out[0], m_out[1], m_out[2] = flow_state(t, flow, mo, mk, pk)


@jit(inline=INLINE)
def flow_state(t, flow, mo, mk, pk):
    """(q_w, q_x, q_y, q_z, M_x, M_y, M_z) at time t of the motion described by flow constants.

    Quaternion scalar first, body → inertial; body momentum. Per call: one sn/cn/dn and the pn of
    the reduced argument (a sine series or one principal-range Π, as the set-up chose), one sin/cos,
    a few square roots; no allocation, and no array view for the caller's loop to make.
    """
    mode = flow[FL_MODE]
    if mode == MODE_UNIFORM:
        th, tl = dd_scale(flow[FL_RATE_HI], flow[FL_RATE_LO], t)
        _, half = dd_remainder(th, tl, TWO_PI_HI, TWO_PI_LO)
        ch, sh = math.cos(half), math.sin(half)
        q = qmul_parts(flow[FL_QN_W], flow[FL_QN_X], flow[FL_QN_Y], flow[FL_QN_Z],
                       ch, sh * flow[FL_AXIS_X], sh * flow[FL_AXIS_Y], sh * flow[FL_AXIS_Z])
        return q[0], q[1], q[2], q[3], flow[FL_M0_X], flow[FL_M0_Y], flow[FL_M0_Z]
    # arg(t) = arg0 + ν t in double-double
    ah, al = dd_scale(flow[FL_RATE_HI], flow[FL_RATE_LO], t)
    ah, al = dd_add(ah, al, flow[FL_ARG0], 0.0)
    gh, gl = dd_scale(flow[FL_G_RATE_HI], flow[FL_G_RATE_LO], t)
    gh, gl = dd_add(gh, gl, flow[FL_G_CONST_HI], flow[FL_G_CONST_LO])
    if flow[FL_PERIODIC] > 0.0:
        j, rh, rl = dd_remainder_dd(ah, al, flow[FL_PERIOD_HI], flow[FL_PERIOD_LO])
        s, c, d = sncndn_reduced(rh, mk[MK_M], mk[MK_MC], mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO])
        ph, pl = flow_kappa_pn(flow, rh, rl, s, c, d, pk)
        gh, gl = dd_add(gh, gl, ph, pl)
        if j != 0.0:
            wh, wl = dd_scale(flow[FL_G_ADVANCE_HI], flow[FL_G_ADVANCE_LO], j)
            gh, gl = dd_add(gh, gl, wh, wl)
            if parity(j) == 1.0:  # sn, cn change sign every half period; dn does not
                s, c = -s, -c
    else:  # separatrix (m = 1): no period; closed forms in the kernels
        r = ah + al
        s, c, d = sncndn_k(r, mk)
        ph, pl = dd_mul(flow[FL_KAPPA_HI], flow[FL_KAPPA_LO], pn_k(r, mk, pk), 0.0)
        gh, gl = dd_add(gh, gl, ph, pl)
    half_g = _reduced_half(gh, gl)
    mx, my, mz, sin_l, cos_l = body_from_sncndn(s, c, d, mo)
    cl, sl = half_angles(sin_l, cos_l)
    # half angles of J (cos J = M_z/G), from whichever of G ± M_z does not cancel
    big_g = mo[MO_G]
    perp = math.sqrt(mx * mx + my * my)  # not hypot (≈ 15 ns): |M| < 1e150 cannot overflow
    if mz >= 0.0:
        cj = math.sqrt(0.5 * (big_g + mz) / big_g)
        sj = perp / (2.0 * big_g * cj)
    else:
        sj = math.sqrt(0.5 * (big_g - mz) / big_g)
        cj = perp / (2.0 * big_g * sj)
    cg, sg = math.cos(half_g), math.sin(half_g)
    # q_z(g) ⊗ q_x(J) ⊗ q_z(l): the 3-1-3 quaternion of Wᵀ R3(g)ᵀ with W = R3(l) R1(J)
    cp, sp = cg * cl - sg * sl, sg * cl + cg * sl  # (g + l)/2
    cm, sm = cg * cl + sg * sl, sg * cl - cg * sl  # (g − l)/2
    q = qmul_parts(flow[FL_QN_W], flow[FL_QN_X], flow[FL_QN_Y], flow[FL_QN_Z],
                   cj * cp, sj * cm, sj * sm, cj * sp)
    flip = flow[FL_FLIP]
    if flip == FLIP_A:  # right factor (0, 1, 0, 0): the π turn about A back to the body frame
        q = (-q[1], q[0], q[3], -q[2])
    elif flip == FLIP_B:
        q = (-q[2], -q[3], q[0], q[1])
    elif flip == FLIP_C:
        q = (-q[3], q[2], -q[1], q[0])
    return q[0], q[1], q[2], q[3], flow[FL_FLIP_X] * mx, flow[FL_FLIP_Y] * my, flow[FL_FLIP_Z] * mz


# --------------------------------------------------------------------------------------------------
# Loops
# --------------------------------------------------------------------------------------------------


@jit
def propagate_many_into(quaternions, momenta, moments, times, q_out, m_out, closed_forms=True):
    """Kernel: N states × T times into preallocated (N, T, 4) and (N, T, 3) arrays.

    ``moments`` is (N, 3) (broadcast by the caller for shared moments). ``closed_forms``: bodies with
    two equal moments take the regular precession (:mod:`.regular_precession`, trig only) instead
    of the elliptic flow at parameter 0; False forces the elliptic flow (tests, benchmarks).

    Consecutive states of one body form a run; within it, blocks of eight rotating states of a
    triaxial body are set up together (:mod:`.flow_blocks`, the same results bit for bit). The other
    states go to :func:`propagate_states_into`, one call per stretch between blocks: in the blocks'
    loop their code cost every block ≈ 10 % of its time and doubled the kernel's compile.
    """
    flows = np.empty((BLOCK, FLOW_SIZE))  # buffers for every state's constants (an allocation each cost ≈ 25 ns)
    mos = np.empty((BLOCK, MO_SIZE))
    stages = np.empty((STAGE_SIZE, BLOCK))
    integrals = np.empty((INTEGRALS_SIZE, BLOCK))
    motions = np.empty((MOTION_SIZE, BLOCK))
    nodes = np.empty((NODE_SIZE, BLOCK))
    n = quaternions.shape[0]
    pending = 0  # states pending … first of a block are left to propagate_states_into, in one call per stretch
    start = 0
    while start < n:
        a, b, c = moments[start, 0], moments[start, 1], moments[start, 2]
        stop = start + 1
        while stop < n and moments[stop, 0] == a and moments[stop, 1] == b and moments[stop, 2] == c:
            stop += 1
        whole = start + (stop - start) // BLOCK * BLOCK
        if whole > start and (not closed_forms or symmetry_axis(a, b, c) == NO_SYMMETRY_AXIS):
            ic, inertia_dd = moment_constants(a, b, c)
            for first in range(start, whole, BLOCK):
                if not _block_rotates(momenta, first):
                    continue
                if pending < first:
                    propagate_states_into(quaternions, momenta, moments, times, q_out, m_out, closed_forms, pending,
                                          first)
                all_periodic = set_up_block_start(flows, mos, stages, motions, quaternions, momenta, first, a, b, c,
                                                  ic, inertia_dd)
                integrals_of_block(stages, integrals, all_periodic)
                nodes_of_block(flows, stages, nodes, quaternions, momenta, first)
                for lane in range(BLOCK):
                    i = first + lane
                    mk, pk = finish_lane(flows, mos, stages, integrals, nodes, lane, quaternions[i], momenta[i], ic)
                    evaluate_into(times, flows[lane], mos[lane], mk, pk, q_out, m_out, i)
                pending = first + BLOCK
        start = stop
    if pending < n:
        propagate_states_into(quaternions, momenta, moments, times, q_out, m_out, closed_forms, pending, n)


@jit
def propagate_states_into(quaternions, momenta, moments, times, q_out, m_out, closed_forms, first, last):
    """Kernel: states first … last − 1 at every time into q_out, m_out, each by itself
    (:func:`propagate_state_into`; the arguments as :func:`propagate_many_into`'s).

    The per-body constants are formed again only where the moments change from one state to the next.
    """
    flow, mo = np.empty(FLOW_SIZE), np.empty(MO_SIZE)
    ic, inertia_dd = moment_constants(moments[first, 0], moments[first, 1], moments[first, 2])
    body = first
    for i in range(first, last):
        a, b, c = moments[i, 0], moments[i, 1], moments[i, 2]
        if a != moments[body, 0] or b != moments[body, 1] or c != moments[body, 2]:
            ic, inertia_dd = moment_constants(a, b, c)
            body = i
        propagate_state_into(quaternions, momenta, times, q_out, m_out, i, a, b, c, closed_forms, flow, mo, ic,
                             inertia_dd)


@jit(inline=INLINE)
def propagate_state_into(quaternions, momenta, times, q_out, m_out, i, a, b, c, closed_forms, flow, mo, ic, inertia_dd):
    """Kernel: state i (moments a ≤ b ≤ c) at every time into q_out[i], m_out[i], by itself: no
    rotation, the regular precession, or the elliptic flow.

    ``flow``, ``mo``: (FLOW_SIZE,) and (MO_SIZE,) buffers; ``ic, inertia_dd``: the body's
    :func:`.phase_constants.moment_constants`. For loops over states that each have their own body
    or times (:func:`propagate_states_into`, :func:`.members.free_flow_each`).
    """
    if momenta[i, 0] == 0.0 and momenta[i, 1] == 0.0 and momenta[i, 2] == 0.0:
        for k in range(times.shape[0]):  # no rotation at all
            q_out[i, k, :] = quaternions[i]
            m_out[i, k, :] = 0.0
        return
    axis = symmetry_axis(a, b, c) if closed_forms else NO_SYMMETRY_AXIS
    if axis != NO_SYMMETRY_AXIS:
        pc = precession_constants(quaternions[i], momenta[i], a, b, c, axis)
        for k in range(times.shape[0]):
            evaluate_precession(times[k], pc, q_out[i, k], m_out[i, k])
        return
    mk, pk = flow_constants_buffers(flow, mo, quaternions[i], momenta[i], a, b, c, ic, inertia_dd)
    evaluate_into(times, flow, mo, mk, pk, q_out, m_out, i)


@jit(inline=INLINE)
def _block_rotates(momenta, first):
    """True if none of states first … first + BLOCK − 1 has a zero momentum."""
    for i in range(first, first + BLOCK):
        if momenta[i, 0] == 0.0 and momenta[i, 1] == 0.0 and momenta[i, 2] == 0.0:
            return False
    return True


@jit(inline=INLINE)
def evaluate_into(times, flow, mo, mk, pk, q_out, m_out, i):
    """The motion at every time into q_out[i] (T, 4) and m_out[i] (T, 3) (flow constants from the
    set-up: :func:`.flow_constants.flow_constants_buffers` or :mod:`.flow_blocks`)."""
    for k in range(times.shape[0]):  # element stores: views q_out[i, k] cost ~10% of an evaluation
        (q_out[i, k, 0], q_out[i, k, 1], q_out[i, k, 2], q_out[i, k, 3],
         m_out[i, k, 0], m_out[i, k, 1], m_out[i, k, 2]) = flow_state(times[k], flow, mo, mk, pk)


#: Largest momentum component the flow takes: its kernels form sums of squares without hypot (for
#: speed), which stay finite below 1e150 (the units layer's RotationState refuses |I ω| outside
#: [1e-150, 1e150] for the same reason).
MAX_MOMENTUM = 1e150


def _as_states(quaternions, momenta, moments):
    q = np.ascontiguousarray(quaternions, dtype=np.float64)
    m = np.ascontiguousarray(momenta, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"quaternions: expected shape (N, 4), got {q.shape}")
    if m.shape != (q.shape[0], 3):
        raise ValueError(f"momenta: expected shape ({q.shape[0]}, 3), got {m.shape}")
    require_finite("quaternions", q, "finite unit quaternions")
    require_finite("momenta", m, "finite body angular momenta")
    if np.any(np.abs(m) > MAX_MOMENTUM):
        raise ValueError(f"momenta: expected components of magnitude ≤ {MAX_MOMENTUM:g} (the flow's sums of squares "
                         f"must not overflow), got up to {float(np.abs(m).max()):.4g}; give them in a larger unit.")
    inertia = np.asarray(moments, dtype=np.float64)
    require_finite("moments", inertia, "finite principal moments")
    if inertia.shape == (3,):
        inertia = np.broadcast_to(inertia, (q.shape[0], 3))
    if inertia.shape != (q.shape[0], 3):
        raise ValueError(f"moments: expected shape (3,) or ({q.shape[0]}, 3), got {inertia.shape}")
    if not np.all((inertia[:, 0] <= inertia[:, 1]) & (inertia[:, 1] <= inertia[:, 2]) & (inertia[:, 0] > 0)):
        raise ValueError("moments: expected principal moments 0 < A ≤ B ≤ C in every row")
    return q, m, np.ascontiguousarray(inertia)


def torque_free_states_many(quaternions, momenta, moments, times, closed_forms=True):
    """Exact torque-free attitudes and body momenta of N states at T times (paper eq. 12).

    Parameters
    ----------
    quaternions : (N, 4) array_like
        Attitudes at t = 0, scalar first, body → inertial (``docs/conventions.md``), unit norm.
    momenta : (N, 3) array_like
        Body angular momenta at t = 0 along the principal axes (A, B, C), mass·length²/time.
    moments : (3,) or (N, 3) array_like
        Principal moments A ≤ B ≤ C (mass·length²), shared or one row per state.
    times : (T,) array_like
        Times since the epoch of the states (the time unit of the momenta).
    closed_forms : bool
        True (default): states of bodies with two exactly equal moments take the regular
        precession in closed form (:mod:`.regular_precession`: two sin/cos, no elliptic function);
        False: every state takes the elliptic flow (for comparisons).

    Returns
    -------
    q : (N, T, 4) ndarray
        Attitude quaternions (scalar first, body → inertial). The sign of a quaternion is not
        continuous in time (q and −q are the same attitude).
    m : (N, T, 3) ndarray
        Body angular momenta.

    Notes
    -----
    The phase is carried as (whole half periods, remainder) with double-double rates, so the
    error does not grow with |t| beyond ≈ 1e-30·|t| (module docstring; ``docs/torque_free.md``).
    """
    q, m, inertia = _as_states(quaternions, momenta, moments)
    t = np.ascontiguousarray(times, dtype=np.float64).reshape(-1)
    require_finite("times", t, "finite times since the states' epoch")
    q_out = np.empty((q.shape[0], t.shape[0], 4))
    m_out = np.empty((q.shape[0], t.shape[0], 3))
    propagate_many_into(q, m, inertia, t, q_out, m_out, bool(closed_forms))
    require_finite_result("torque_free_states_many: the attitudes", q_out,
                          "a phase rate × time or a momentum beyond what the flow's arithmetic carries")
    require_finite_result("torque_free_states_many: the momenta", m_out,
                          "a phase rate × time or a momentum beyond what the flow's arithmetic carries")
    return q_out, m_out


def torque_free_states(quaternion, momentum, big_a, big_b, big_c, times, closed_forms=True):
    """Exact torque-free attitude and body momentum of one state at T times (paper eq. 12).

    Parameters
    ----------
    quaternion : (4,) array_like
        Attitude at t = 0, scalar first, body → inertial.
    momentum : (3,) array_like
        Body angular momentum at t = 0 (principal axes A ≤ B ≤ C), mass·length²/time.
    big_a, big_b, big_c : float
        Principal moments A ≤ B ≤ C (mass·length²).
    times : (T,) array_like
        Times since the epoch of the state.
    closed_forms : bool
        As in :func:`torque_free_states_many`.

    Returns
    -------
    q : (T, 4) ndarray
        Quaternions (scalar first, body → inertial).
    m : (T, 3) ndarray
        Body angular momenta.
    """
    q_out, m_out = torque_free_states_many(
        np.reshape(quaternion, (1, 4)), np.reshape(momentum, (1, 3)), (big_a, big_b, big_c), times,
        closed_forms,
    )
    return q_out[0], m_out[0]


@jit
def torque_free_attitudes(attitude, momentum, big_a, big_b, big_c, times):
    """Exact torque-free attitude matrices (inertial → body) at many times, (T, 3, 3) (eq. 12).

    Matrix form of :func:`torque_free_states` for callers that hold attitude matrices (closed form
    for axisymmetric bodies, as there).
    """
    n = times.shape[0]
    out = np.empty((n, 3, 3))
    q0 = attitude_to_quat(attitude)
    q = np.empty(4)
    m = np.empty(3)
    if momentum[0] == 0.0 and momentum[1] == 0.0 and momentum[2] == 0.0:
        for i in range(n):
            out[i] = attitude
        return out
    axis = symmetry_axis(big_a, big_b, big_c)
    if axis != NO_SYMMETRY_AXIS:
        pc = precession_constants(q0, momentum, big_a, big_b, big_c, axis)
        for i in range(n):
            evaluate_precession(times[i], pc, q, m)
            out[i] = quat_to_attitude(q)
        return out
    flow, mo, mk, pk = flow_constants(q0, momentum, big_a, big_b, big_c)
    for i in range(n):
        evaluate_flow(times[i], flow, mo, mk, pk, q, m)
        out[i] = quat_to_attitude(q)
    return out


@jit
def uniform_rotation(attitude, momentum, big_a, big_b, big_c, t):
    """Attitude matrix at time t of a permanent rotation (ω = I⁻¹M parallel to M).

    R(t) = R_ω(t) R0, R_ω(t) the passive rotation by |ω| t about ω, with |ω| t/2 carried in
    double-double (the same path as :func:`torque_free_states` for MODE_UNIFORM; a symmetric body
    takes the regular precession, which is this uniform rotation when the spin is perpendicular to
    its symmetry axis).
    """
    times = np.array([t])
    return torque_free_attitudes(attitude, momentum, big_a, big_b, big_c, times)[0]
