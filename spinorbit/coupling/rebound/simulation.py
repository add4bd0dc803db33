"""A REBOUND simulation of the Solar System from DE421, its particles by name, and reads from them.

:func:`simulation_from_de421` builds a ``rebound.Simulation`` offline at an astropy ``Time``: units
("AU", "day", "Msun"), so that G = k² = DE421's GM_Sun; masses GM/G; ``sim.t`` in TDB days since
J2000; barycentric ICRF, moved to the centre of mass; ``exact_finish_time = 1`` (REBOUND has no
dense output, so every output time must be hit exactly). "AU" is DE421's astronomical unit
(:mod:`spinorbit.ephemeris` explains the 2.5e-12 difference from IAU 2012's).

:func:`body_index` finds a particle by name; :func:`perturber_positions` reads positions relative to
a named body straight out of REBOUND's particle array into numpy.
"""

from __future__ import annotations

import numpy as np
import rebound

from spinorbit.core.errors import SpinorbitError
from spinorbit.coupling.rebound.memory_layout import PARTICLE_M, PARTICLE_X, particle_table
from spinorbit.ephemeris import KNOWN_BODIES, barycentric_state_au, de421_constants, resolve_body
from spinorbit.time import tdb_day_and_fraction

__all__ = ["DEFAULT_BODIES", "MissingBodyError", "simulation_from_de421", "body_index", "perturber_positions"]

#: Bodies of :func:`simulation_from_de421` by default: every body DE421 has here (Sun, the planets'
#: system barycentres, Earth and Moon separately, Pluto's system barycentre) but the Earth–Moon
#: barycentre, which would count Earth and Moon twice. REBOUND names are these, capitalised.
DEFAULT_BODIES = tuple(body for body in KNOWN_BODIES if body != "earth-moon barycenter")


class MissingBodyError(SpinorbitError, LookupError):
    """A body the caller named is not in the REBOUND simulation."""


def _rebound_name(body: str) -> str:
    return body.strip().capitalize()


def simulation_from_de421(time, bodies=DEFAULT_BODIES, integrator: str = "ias15"):
    """A REBOUND simulation with DE421 states at ``time``, built offline.

    Parameters
    ----------
    time : astropy.time.Time
        Scalar epoch, any scale convertible to TDB, within DE421's span.
    bodies : sequence of str, optional
        Names from :data:`spinorbit.ephemeris.KNOWN_BODIES`; default :data:`DEFAULT_BODIES`.
        Particles are named by the capitalised names ('Sun', 'Earth', 'Moon', ...).
    integrator : str, optional
        REBOUND integrator name (default 'ias15'). Use 'bs' when a user ODE must be coupled
        (``docs/coupling.md``).

    Returns
    -------
    rebound.Simulation
        Units ("AU", "day", "Msun"); masses GM/G with DE421 GMs (au³/day²); ``t`` = TDB days since
        J2000 (as one float; its rounding is ≤ 0.31 µs in 1900–2100); barycentric ICRF positions
        (au_DE421) and velocities (au/day), moved to the centre of mass of the chosen bodies;
        ``exact_finish_time = 1``.

    Raises
    ------
    TypeError
        If ``time`` is not a scalar astropy ``Time``.
    spinorbit.ephemeris.UnknownBodyError, spinorbit.ephemeris.EphemerisRangeError
    """
    day, fraction = tdb_day_and_fraction(time)
    if np.ndim(day) != 0:
        raise TypeError(
            f"time must be a scalar Time (one epoch); got an array of shape {np.shape(day)}."
        )
    constants = de421_constants()
    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.integrator = integrator
    sim.t = day + fraction
    for body in bodies:
        name = resolve_body(body)
        position, velocity = barycentric_state_au(name, day, fraction)
        sim.add(
            m=constants.gm[name] / sim.G,
            x=position[0], y=position[1], z=position[2],
            vx=velocity[0], vy=velocity[1], vz=velocity[2],
            name=_rebound_name(name),
        )
    sim.move_to_com()
    sim.exact_finish_time = 1
    return sim


def body_index(sim, body: str) -> int:
    """Index of the particle named ``body`` (case-insensitive) in ``sim``.

    Raises
    ------
    MissingBodyError
        If no particle has that name; the message lists the names present.
    """
    wanted = _rebound_name(body)
    names = [particle.name for particle in sim.particles]
    for index, name in enumerate(names):
        if name is not None and name.capitalize() == wanted:
            return index
    raise MissingBodyError(
        f"the simulation has no particle named {body!r}; it has {names}. Add it (with name=...) or "
        "build the simulation with spinorbit.coupling.rebound.simulation_from_de421."
    )


def perturber_positions(sim, body: str, perturbers=None):
    """Positions of perturbers relative to ``body``, read from the running simulation.

    Parameters
    ----------
    sim : rebound.Simulation
        A simulation in ("AU", "day", "Msun") units with named particles.
    body : str
        The body whose rotation is being integrated (e.g. 'Moon').
    perturbers : sequence of str, optional
        Names to read; default every other named particle, in simulation order.

    Returns
    -------
    positions : ndarray, shape (k, 3), unit: au_DE421
        r_perturber − r_body in ICRF axes, at ``sim.t`` (TDB days since J2000).
    gm : ndarray, shape (k,), unit: au³/day²
        G·m of each perturber.
    names : tuple of str
        The perturbers' names, in the order of the rows.

    Raises
    ------
    MissingBodyError
        If ``body`` or a named perturber is not in the simulation.
    """
    centre = body_index(sim, body)
    if perturbers is None:
        indices = [i for i, p in enumerate(sim.particles) if i != centre and p.name is not None]
    else:
        indices = [body_index(sim, name) for name in perturbers]
    table = particle_table(sim)  # no copy, no per-particle Python objects
    index = np.asarray(indices, dtype=np.intp)
    positions = table[index, PARTICLE_X:PARTICLE_X + 3] - table[centre, PARTICLE_X:PARTICLE_X + 3]
    gm = table[index, PARTICLE_M] * sim.G
    names = tuple(sim.particles[i].name for i in indices)
    return positions, gm, names
