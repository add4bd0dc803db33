"""What a state's torque-free motion is: rotation mode, E/E0, the periods P_ψ, P_φ and the sidereal period.

The one definition of these quantities: :class:`spinorbit.RotationState` (``mode``,
``energy_ratio``, ``periods``, ``sidereal_period``) calls the scalar kernels for one state, and the output tables of
:class:`spinorbit.scene.scene.Scene` and :func:`spinorbit.coupling.one_way.propagate_one_way` call
:func:`motion_summary_many` for all rows at once (one compiled loop instead of one Python object per
row). All are functions of the body momentum (principal axes A ≤ B ≤ C) alone, through G and T: they
are constants of the torque-free motion (paper eq. 12 keeps S and Z), and osculating values of a
torqued one.

Permanent rotation is the momentum exactly along a principal axis (:func:`on_principal_axis`): along B
the motion constants say so themselves (``MODE_UNIFORM``), along C or A they describe a SAM or LAM of
zero amplitude, whose elliptic periods are the *small-wobble limits* (the polhode period
2π/(G√((a−c)(b−c))) about C), not a principal rotator's. Those limits are what a state a hair off the
axis has: P_ψ and P_φ are discontinuous at the axis by their definition (a wobble of zero amplitude
has no period), while the sidereal period is continuous there (``docs/conventions.md``, "Periods").
"""

import math

from spinorbit.core.elements.canonical import (
    MO_ARG_PER_S,
    MO_G,
    MO_MODE,
    MO_PARAM_C,
    MO_PN_COEFF,
    MO_PN_N,
    MO_X_AMP,
    MO_Y_AMP,
    MO_S_RATE,
    MODE_LAM,
    MODE_SAM,
    MODE_UNIFORM,
    inertia_constants,
    motion_from_momentum,
)
from spinorbit.core.jit import jit
from spinorbit.core.math.elliptic_integrals import complete_k_pi

#: Mode code of a motion on the separatrix (SAM formulas at 1 − m = 0 exactly), next to
#: ``canonical.MODE_SAM``, ``MODE_LAM`` and ``MODE_UNIFORM`` (permanent rotation).
MODE_SEPARATRIX = 2


@jit
def on_principal_axis(mo):
    """True when the momentum of motion ``mo`` lies exactly along a principal axis (permanent rotation).

    Along B (or in the equal-moment plane of a symmetric body) the mode is ``MODE_UNIFORM``; along C
    a SAM has no M_x, M_y amplitude (X ∝ √(d − c) = 0), along A a LAM none in M_y, M_z (Y ∝ √(a − d) = 0).
    """
    if mo[MO_MODE] == MODE_UNIFORM:
        return True
    if mo[MO_MODE] == MODE_SAM:
        return mo[MO_X_AMP] == 0.0
    return mo[MO_Y_AMP] == 0.0


@jit
def mode_code(mo):
    """MODE_SAM, MODE_LAM, MODE_UNIFORM (permanent rotation about A, B or C) or MODE_SEPARATRIX of ``mo``."""
    if on_principal_axis(mo):
        return MODE_UNIFORM
    if mo[MO_MODE] == MODE_SAM and mo[MO_PARAM_C] == 0.0:
        return MODE_SEPARATRIX
    return int(mo[MO_MODE])


@jit
def energy_ratio(mx, my, mz, big_a, big_b, big_c):
    """E/E0 = 2 T C / G² of body momentum (M_x, M_y, M_z): the kinetic energy over that of rotation
    about C with the same momentum (1 about C, C/A about A, C/B on the separatrix)."""
    return (mx * mx / big_a + my * my / big_b + mz * mz / big_c) * big_c / (mx * mx + my * my + mz * mz)


@jit
def spin_rate(mx, my, mz, big_a, big_b, big_c):
    """|ω| = |I⁻¹ M| (rad per time unit of the momentum)."""
    wx, wy, wz = mx / big_a, my / big_b, mz / big_c
    return math.sqrt(wx * wx + wy * wy + wz * wz)


@jit
def polhode_rates(mo, big_c):
    """(P_ψ, ⟨ġ⟩) of a motion off the principal axes and off the separatrix.

    P_ψ = 4K/ν is the period of the body momentum's circulation, ν the rate of the elliptic argument;
    ⟨ġ⟩ = c G + PN_COEFF · Π(n|p)/K(p) · ν is the Andoyer g's rate (C-axis reference, paper eq. 7)
    averaged over that period.
    """
    # K(p) and Π(n|p) (n ≤ 0 in both modes) from one AGM in doubles (DLMF 19.8.5–8), instead of a
    # double-double AGM for K and Carlson's R_F and R_J for Π: the periods are doubles (a few ε)
    quarter, complete_pi = complete_k_pi(-mo[MO_PN_N], mo[MO_PARAM_C])
    nu = mo[MO_ARG_PER_S] * mo[MO_S_RATE]
    return 4.0 * quarter / nu, mo[MO_G] / big_c + mo[MO_PN_COEFF] * complete_pi / quarter * nu


@jit
def all_periods(mo, mx, my, mz, big_a, big_b, big_c):
    """(P_ψ, P_φ, P_sid) of :func:`periods` and :func:`sidereal_period` with one evaluation of K and Π."""
    if on_principal_axis(mo):
        rotation = 2.0 * math.pi / spin_rate(mx, my, mz, big_a, big_b, big_c)
        return math.inf, rotation, rotation
    if mo[MO_PARAM_C] == 0.0:
        return math.inf, math.inf, 2.0 * math.pi * big_b / mo[MO_G]
    rotation_period, mean_g_rate = polhode_rates(mo, big_c)
    turn_rate = 2.0 * math.pi / rotation_period
    if mo[MO_MODE] == MODE_LAM:
        # In LAM, l librates and the long axis A circulates about the momentum: its azimuth gains one
        # turn less than g per polhode period; the body turns about the momentum at ⟨ġ⟩ itself.
        return rotation_period, 2.0 * math.pi / (mean_g_rate - turn_rate), 2.0 * math.pi / mean_g_rate
    # In SAM, the C axis's azimuth follows g; l circulates against g, so the body turns at ⟨ġ⟩ − 2π/P_ψ.
    return rotation_period, 2.0 * math.pi / mean_g_rate, 2.0 * math.pi / (mean_g_rate - turn_rate)


@jit
def periods(mo, mx, my, mz, big_a, big_b, big_c):
    """(P_ψ, P_φ) in the time unit of the momentum (day for rad/day), Pravec et al. (2005) convention.

    P_ψ = 4K/ν is the period of the body momentum's circulation (SAM: about C; LAM: about A), with ν
    the rate of the elliptic argument. P_φ is the mean precession period about the momentum of the
    circulation axis: in SAM the C axis, whose azimuth follows g, so P_φ = 2π/⟨ġ⟩ with
    ⟨ġ⟩ = c G + PN_COEFF · Π(n|p)/K(p) · ν (paper eq. 7 averaged over a period); in LAM the long
    axis A, which gains one turn less per polhode period: P_φ = 2π/(⟨ġ⟩ − 2π/P_ψ). Both are infinite
    on the separatrix; a permanent rotation (momentum exactly along A, B or C) has P_ψ = ∞ and
    P_φ = 2π/|ω|.
    """
    p_psi, p_phi, _ = all_periods(mo, mx, my, mz, big_a, big_b, big_c)
    return p_psi, p_phi


@jit
def sidereal_period(mo, mx, my, mz, big_a, big_b, big_c):
    """The sidereal rotation period: 2π/|ω| for a permanent rotation, its continuation for a tumbler.

    For a tumbler it is 2π over the mean rate at which the body turns about its angular momentum,
    ⟨ġ + l̇⟩ (Andoyer angles, C reference): in SAM l circulates against g, so 2π/(⟨ġ⟩ − 2π/P_ψ), i.e.
    1/(1/P_φ − 1/P_ψ); in LAM l librates, so 2π/⟨ġ⟩, i.e. 1/(1/P_φ + 1/P_ψ). Those are the lightcurve
    combination frequencies that become the rotation frequency as the wobble vanishes: the value is
    continuous as the momentum approaches A or C (and → 2π B/G at the separatrix, from both sides),
    where P_ψ and P_φ are not. On the separatrix itself it is 2π B/G, the rotation the motion tends to.
    """
    return all_periods(mo, mx, my, mz, big_a, big_b, big_c)[2]


@jit
def motion_summary(mx, my, mz, big_a, big_b, big_c):
    """(mode code, E/E0, P_ψ, P_φ, sidereal period) of the torque-free motion through body momentum M (M ≠ 0)."""
    mo, _ = motion_from_momentum(mx, my, mz, inertia_constants(big_a, big_b, big_c))
    p_psi, p_phi, p_sidereal = all_periods(mo, mx, my, mz, big_a, big_b, big_c)
    return mode_code(mo), energy_ratio(mx, my, mz, big_a, big_b, big_c), p_psi, p_phi, p_sidereal


@jit
def motion_summary_many(momenta, big_a, big_b, big_c, modes, ratios, p_psi, p_phi, p_sidereal):
    """:func:`motion_summary` of every row of ``momenta`` (N, 3) into the (N,) output arrays."""
    for i in range(momenta.shape[0]):
        modes[i], ratios[i], p_psi[i], p_phi[i], p_sidereal[i] = motion_summary(
            momenta[i, 0], momenta[i, 1], momenta[i, 2], big_a, big_b, big_c)
