"""What a state's torque-free motion is: rotation mode, E/E0 and the periods P_ψ, P_φ.

The one definition of these quantities: :class:`spinorbit.RotationState` (``mode``,
``energy_ratio``, ``periods``) calls the scalar kernels for one state, and the output tables of
:class:`spinorbit.scene.scene.Scene` and :func:`spinorbit.coupling.one_way.propagate_one_way` call
:func:`motion_summary_many` for all rows at once (one compiled loop instead of one Python object per
row). All are functions of the body momentum (principal axes A ≤ B ≤ C) alone, through G and T: they
are constants of the torque-free motion (paper eq. 12 keeps S and Z), and osculating values of a
torqued one.
"""

import math

from spinorbit.core.elements.canonical import (
    MO_ARG_PER_S,
    MO_G,
    MO_MODE,
    MO_PARAM,
    MO_PARAM_C,
    MO_PN_COEFF,
    MO_PN_N,
    MO_S_RATE,
    MODE_LAM,
    MODE_SAM,
    MODE_UNIFORM,
    inertia_constants,
    motion_from_momentum,
)
from spinorbit.core.jit import jit
from spinorbit.core.math.elliptic_integrals import NK_COMPLETE, characteristic_constants
from spinorbit.core.math.elliptic_periods import ellipk

#: Mode code of a motion on the separatrix (SAM formulas at 1 − m = 0 exactly), next to
#: ``canonical.MODE_SAM``, ``MODE_LAM`` and ``MODE_UNIFORM`` (permanent rotation).
MODE_SEPARATRIX = 2


@jit
def mode_code(mo):
    """MODE_SAM, MODE_LAM, MODE_UNIFORM or MODE_SEPARATRIX of motion constants ``mo``."""
    if mo[MO_MODE] == MODE_SAM and mo[MO_PARAM_C] == 0.0:
        return MODE_SEPARATRIX
    return int(mo[MO_MODE])


@jit
def energy_ratio(mx, my, mz, big_a, big_b, big_c):
    """E/E0 = 2 T C / G² of body momentum (M_x, M_y, M_z): the kinetic energy over that of rotation
    about C with the same momentum (1 about C, C/A about A, C/B on the separatrix)."""
    return (mx * mx / big_a + my * my / big_b + mz * mz / big_c) * big_c / (mx * mx + my * my + mz * mz)


@jit
def periods(mo, mx, my, mz, big_a, big_b, big_c):
    """(P_ψ, P_φ) in the time unit of the momentum (day for rad/day), Pravec et al. (2005) convention.

    P_ψ = 4K/ν is the period of the body momentum's circulation (SAM: about C; LAM: about A), with ν
    the rate of the elliptic argument. P_φ is the mean precession period about the momentum of the
    circulation axis: in SAM the C axis, whose azimuth follows g, so P_φ = 2π/⟨ġ⟩ with
    ⟨ġ⟩ = c G + PN_COEFF · Π(n|p)/K(p) · ν (paper eq. 7 averaged over a period); in LAM the long
    axis A, which gains one turn less per polhode period: P_φ = 2π/(⟨ġ⟩ − 2π/P_ψ). Both are infinite
    on the separatrix; a permanent rotation has P_ψ = ∞ and P_φ = 2π/|ω|.
    """
    if mo[MO_MODE] == MODE_UNIFORM:
        wx, wy, wz = mx / big_a, my / big_b, mz / big_c
        return math.inf, 2.0 * math.pi / math.sqrt(wx * wx + wy * wy + wz * wz)
    param, param_c = mo[MO_PARAM], mo[MO_PARAM_C]
    if param_c == 0.0:
        return math.inf, math.inf
    quarter = ellipk(param, param_c)
    complete_pi = characteristic_constants(mo[MO_PN_N], param, param_c)[NK_COMPLETE]
    nu = mo[MO_ARG_PER_S] * mo[MO_S_RATE]
    mean_g_rate = mo[MO_G] / big_c + mo[MO_PN_COEFF] * complete_pi / quarter * nu
    rotation_period = 4.0 * quarter / nu
    if mo[MO_MODE] == MODE_LAM:
        # In LAM, l librates and the long axis A circulates about the momentum: its azimuth gains
        # one turn less than g per polhode period.
        mean_g_rate -= 2.0 * math.pi / rotation_period
    return rotation_period, 2.0 * math.pi / mean_g_rate


@jit
def motion_summary(mx, my, mz, big_a, big_b, big_c):
    """(mode code, E/E0, P_ψ, P_φ) of the torque-free motion through body momentum M (M ≠ 0)."""
    mo, _ = motion_from_momentum(mx, my, mz, inertia_constants(big_a, big_b, big_c))
    p_psi, p_phi = periods(mo, mx, my, mz, big_a, big_b, big_c)
    return mode_code(mo), energy_ratio(mx, my, mz, big_a, big_b, big_c), p_psi, p_phi


@jit
def motion_summary_many(momenta, big_a, big_b, big_c, modes, ratios, p_psi, p_phi):
    """:func:`motion_summary` of every row of ``momenta`` (N, 3) into the (N,) output arrays."""
    for i in range(momenta.shape[0]):
        modes[i], ratios[i], p_psi[i], p_phi[i] = motion_summary(
            momenta[i, 0], momenta[i, 1], momenta[i, 2], big_a, big_b, big_c)
