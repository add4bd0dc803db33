"""The wobble amplitude of a torque-free motion: how far its circulation axis nods from the angular momentum.

In free rotation the angular momentum L is fixed in space and the body momentum M (principal axes,
A ≤ B ≤ C) runs round its polhode on the sphere |M| = G. The axis the polhode circles — C in SAM, A in
LAM — makes the nutation angle θ with L: cos θ = |M_z|/G (SAM) or |M_x|/G (LAM). θ oscillates between
two extremes once per half polhode period. The wobble amplitude is its largest value,

    SAM:  sin²θ_max = (M_y² + M_x² · B(C − A) / (A(C − B))) / G²,
    LAM:  sin²θ_max = (M_y² + M_z² · B(C − A) / (C(B − A))) / G²,

reached where the polhode crosses M_x = 0 (SAM) or M_z = 0 (LAM), where the intermediate axis carries
as much of the momentum as the energy allows. Both follow from the two integrals G² = ΣM_i² and
2T = ΣM_i²/I_i alone, by eliminating the component that vanishes at the extreme. In the Jacobi solution
(Landau & Lifshitz, *Mechanics* §37; the paper's eq. 12 in elements) M_z ∝ dn in SAM and M_x ∝ dn in
LAM: θ_max is where dn takes its smallest value √(1 − k²). The cosine side is formed as the
circulation-axis term minus the other one scaled by C(B − A)/(A(C − B)) (SAM) or A(C − B)/(C(B − A))
(LAM), so no 1 − sin² cancels: θ_max keeps its relative accuracy near 0 (principal-axis rotators) and
its absolute accuracy near 90° (the separatrix, where both modes' amplitudes tend to 90°).

The amplitude is a function of the body momentum alone, a constant of the torque-free motion and the
osculating value of a torqued one. Permanent rotation (M exactly along A, B or C) has amplitude 0; the
separatrix π/2. ``docs/conventions.md``, "Wobble and rotation class".
"""

import math

from spinorbit.core.elements.canonical import (
    MODE_SAM,
    MODE_UNIFORM,
    inertia_constants,
    motion_from_momentum,
)
from spinorbit.core.free_motion.summary import MODE_SEPARATRIX, mode_code
from spinorbit.core.jit import jit


@jit
def amplitude_of_mode(code, mx, my, mz, big_a, big_b, big_c):
    """θ_max (rad, in [0, π/2]) of body momentum M in principal axes, for its mode ``code`` (summary.mode_code)."""
    if code == MODE_UNIFORM:
        return 0.0
    if code == MODE_SEPARATRIX:
        return 0.5 * math.pi
    if code == MODE_SAM:
        # B < C here (a body with B = C has no SAM); A = B gives the regular precession's constant angle
        spread = big_b * (big_c - big_a) / (big_a * (big_c - big_b))
        excess = big_c * (big_b - big_a) / (big_a * (big_c - big_b))  # spread − 1, formed without cancelling
        sine_side = my * my + mx * mx * spread
        cosine_side = mz * mz - mx * mx * excess
    else:
        # A < B here (a body with A = B has no LAM)
        spread = big_b * (big_c - big_a) / (big_c * (big_b - big_a))
        excess = big_a * (big_c - big_b) / (big_c * (big_b - big_a))
        sine_side = my * my + mz * mz * spread
        cosine_side = mx * mx - mz * mz * excess
    return math.atan2(math.sqrt(max(sine_side, 0.0)), math.sqrt(max(cosine_side, 0.0)))


@jit
def wobble_amplitude(mx, my, mz, big_a, big_b, big_c):
    """θ_max (rad) of the torque-free motion through body momentum (M_x, M_y, M_z) ≠ 0, principal axes A ≤ B ≤ C."""
    mo, _ = motion_from_momentum(mx, my, mz, inertia_constants(big_a, big_b, big_c))
    return amplitude_of_mode(mode_code(mo), mx, my, mz, big_a, big_b, big_c)


@jit
def wobble_amplitude_many(momenta, big_a, big_b, big_c, out):
    """:func:`wobble_amplitude` of every row of ``momenta`` (N, 3) into ``out`` (N,)."""
    for i in range(momenta.shape[0]):
        out[i] = wobble_amplitude(momenta[i, 0], momenta[i, 1], momenta[i, 2], big_a, big_b, big_c)

