"""Is the pair still a binary? The mutual orbit's energy, and the Sun's Hill sphere when it acts.

A mutual period or a libration line means something only while B orbits A. Two tests, at every
output time of a run:

- **energy**: the orbit's two-body energy E_orb = ½ ν |Ṙ|² − U(R, q_A, q_B) (ν the reduced mass,
  U the truncated mutual potential with its figure terms, :func:`.equations.field_into`) is < 0.
  With E_orb ≥ 0 the point-mass part of the relative orbit is an open conic and the figure terms
  fall off as 1/R³ and faster, so B leaves. E_orb is not conserved (the torques trade it with both
  spins), so it is tested at every output time, not only at the start;
- **Hill sphere** (only with the Sun's tide on): the separation is below the pair's Hill radius at
  the heliocentric pericentre, r_H = a (1 − e) (G (m_A + m_B) / (3 μ_sun))^{1/3}
  (the pericentre Hill radius of Hamilton & Burns 1992, Icarus 96, 43): farther out the Sun, not A, holds B.

A run whose state fails either test at some output time has no mutual period: the units layer
raises :class:`~.errors.UnboundPairError` instead of reporting one.
"""

import math

import numpy as np

from spinorbit.core.binary.equations import (
    M_G,
    M_MASS_A,
    M_MASS_B,
    M_SUN,
    M_SUN_MU,
    M_SUN_ORBIT,
    POSITION,
    SCRATCH_SIZE,
    VELOCITY,
    field_into,
)
from spinorbit.core.jit import jit
from spinorbit.core.model.perturbers import K_A, K_E

#: Reasons of :func:`first_unbound`.
BOUND, ENERGY, HILL = 0, 1, 2


@jit
def orbit_energy(y, model):
    """E_orb = ½ ν |Ṙ|² − U of state y (J in SI): the relative orbit's energy with the figure terms of U."""
    u = field_into(y, model, np.zeros(SCRATCH_SIZE))[0]
    reduced_mass = 1.0 / (1.0 / model[M_MASS_A] + 1.0 / model[M_MASS_B])
    v2 = y[VELOCITY] ** 2 + y[VELOCITY + 1] ** 2 + y[VELOCITY + 2] ** 2
    return 0.5 * reduced_mass * v2 - u


@jit
def orbit_energies(ys, model):
    """:func:`orbit_energy` of each row of ys (n, 20)."""
    out = np.empty(ys.shape[0])
    for k in range(ys.shape[0]):
        out[k] = orbit_energy(ys[k], model)
    return out


@jit
def hill_radius(model):
    """The pair's Hill radius at the Sun's pericentre (length), or +inf with the Sun's tide off."""
    if model[M_SUN] == 0.0:
        return math.inf
    a = model[M_SUN_ORBIT + K_A]
    e = model[M_SUN_ORBIT + K_E]
    ratio = model[M_G] * (model[M_MASS_A] + model[M_MASS_B]) / (3.0 * model[M_SUN_MU])
    return a * (1.0 - e) * ratio ** (1.0 / 3.0)


@jit
def first_unbound(ys, model):
    """(index, reason, value) of the first row of ys where the pair is not bound, or (−1, BOUND, 0).

    ``reason`` is ENERGY (``value`` = E_orb ≥ 0) or HILL (``value`` = the separation beyond
    :func:`hill_radius`). A NaN energy or separation counts as unbound: nothing is reported from it.
    """
    limit = hill_radius(model)
    for k in range(ys.shape[0]):
        energy = orbit_energy(ys[k], model)
        if not energy < 0.0:
            return k, ENERGY, energy
        r = math.sqrt(ys[k, POSITION] ** 2 + ys[k, POSITION + 1] ** 2 + ys[k, POSITION + 2] ** 2)
        if not r < limit:
            return k, HILL, r
    return -1, BOUND, 0.0
