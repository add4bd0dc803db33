"""Many torque-free members at once: each its own body, its own times, its motion's constants (one loop).

An ensemble of torque-free members (``spinorbit.ensemble.free``) differs from
:func:`.flow.torque_free_states_many` in two ways: every member has its own moments *and* its own
output times (members need not share an epoch), and the outcome also needs the constants of each
motion (mode, E/E0, P_ψ, P_φ, sidereal period, :func:`.summary.motion_summary`). One compiled loop
each, with no Python per member: :func:`motion_summary_each` for the constants of the member's
initial momentum, :func:`free_flow_each` for the flow, which is :func:`.flow.propagate_state_into`
on the member's row (the same set-up and evaluation as every other caller of the flow).

A member's numbers depend on its own inputs only (nothing is shared across the loop), so a member
evaluated alone and in any batch gives the same bits (``tests/test_ensemble_free.py``).
"""

import numpy as np

from spinorbit.core.elements.canonical import MO_SIZE
from spinorbit.core.free_motion.flow import FLOW_SIZE, propagate_state_into
from spinorbit.core.free_motion.phase_constants import moment_constants
from spinorbit.core.free_motion.summary import motion_summary
from spinorbit.core.jit import jit

__all__ = ["free_flow_each", "free_members", "motion_summary_each"]


@jit
def motion_summary_each(momenta, moments, modes, ratios, p_psi, p_phi, p_sidereal):
    """:func:`.summary.motion_summary` of every member, each with its own moments ``moments[i]`` (A ≤ B ≤ C)."""
    for i in range(momenta.shape[0]):
        modes[i], ratios[i], p_psi[i], p_phi[i], p_sidereal[i] = motion_summary(
            momenta[i, 0], momenta[i, 1], momenta[i, 2], moments[i, 0], moments[i, 1], moments[i, 2])


@jit
def free_flow_each(quaternions, momenta, moments, elapsed, q_out, m_out):
    """Kernel: the exact flow of N members, member i at its own times ``elapsed[i]`` (K each).

    Parameters
    ----------
    quaternions : (N, 4) float64
        Principal-axis attitudes (scalar first, body → inertial) at each member's epoch.
    momenta : (N, 3) float64
        Body angular momenta along the principal axes A ≤ B ≤ C, non-zero.
    moments : (N, 3) float64
        Principal moments A ≤ B ≤ C of each member.
    elapsed : (N, K) float64
        Times since each member's epoch (the time unit of the momenta).
    q_out, m_out : (N, K, 4), (N, K, 3) float64
        Attitudes and body momenta at those times (paper eq. 12).
    """
    flow, mo = np.empty(FLOW_SIZE), np.empty(MO_SIZE)
    for i in range(quaternions.shape[0]):
        a, b, c = moments[i, 0], moments[i, 1], moments[i, 2]
        ic, inertia_dd = moment_constants(a, b, c)
        propagate_state_into(quaternions, momenta, elapsed[i], q_out, m_out, i, a, b, c, True, flow, mo, ic, inertia_dd)


def free_members(quaternions, momenta, moments, elapsed=None):
    """(modes, ratios, p_psi, p_phi, p_sidereal, q, m) of N members; q, m are None without ``elapsed``.

    Inputs are taken as contiguous float64 arrays of the shapes :func:`free_flow_each` documents
    (``elapsed`` (N, K), or None for the constants alone); the caller checks them
    (``spinorbit.ensemble.free`` does, with the reasons). Periods in the time unit of the momenta.
    """
    q = np.ascontiguousarray(quaternions, dtype=np.float64)
    m = np.ascontiguousarray(momenta, dtype=np.float64)
    inertia = np.ascontiguousarray(moments, dtype=np.float64)
    n = q.shape[0]
    modes = np.empty(n, dtype=np.int64)
    ratios, p_psi, p_phi, p_sidereal = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    motion_summary_each(m, inertia, modes, ratios, p_psi, p_phi, p_sidereal)
    if elapsed is None:
        return modes, ratios, p_psi, p_phi, p_sidereal, None, None
    times = np.ascontiguousarray(elapsed, dtype=np.float64)
    q_out, m_out = np.empty((n, times.shape[1], 4)), np.empty((n, times.shape[1], 3))
    free_flow_each(q, m, inertia, times, q_out, m_out)
    return modes, ratios, p_psi, p_phi, p_sidereal, q_out, m_out
