"""A small body (massless) among DE421's planets in REBOUND, with the force model of the Apophis orbit.

:func:`small_body_simulation` is the one place a published or user orbit becomes a REBOUND run:
the Sun, planets, Moon and Pluto from DE421 at the epoch
(:func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421`), the body added as a massless
particle at a heliocentric (or barycentric) ICRF state, and — as JPL's small-body model has them —
the EIH 1PN terms and Earth's J2
(:func:`~spinorbit.coupling.rebound.extra_forces.install_extra_forces`), with the body's own
non-gravitational A1, A2, A3 (:func:`~spinorbit.coupling.rebound.extra_forces.set_nongravitational`)
when given. Left out: the asteroid perturbers (``docs/asteroids.md``). Units: DE421's au and
au/day, ``t`` in TDB days since J2000; IAS15 with ``exact_finish_time``.
"""

from __future__ import annotations

import numpy as np

from spinorbit.coupling.rebound.extra_forces import install_extra_forces, set_nongravitational
from spinorbit.coupling.rebound.simulation import DEFAULT_BODIES, body_index, simulation_from_de421

__all__ = ["CENTRES", "small_body_simulation"]

#: What a small body's state may be relative to.
CENTRES = ("sun", "barycenter")


def small_body_simulation(name, epoch, position_au, velocity_au_day, centre="sun", bodies=DEFAULT_BODIES,
                          integrator="ias15", extra_forces=True, non_gravitational=None):
    """REBOUND simulation at ``epoch`` with the DE421 bodies and one massless small body.

    Parameters
    ----------
    name : str
        The particle's name.
    epoch : astropy.time.Time
        Scalar, inside DE421's span (else :class:`~spinorbit.ephemeris.EphemerisRangeError`).
    position_au, velocity_au_day : array_like, shape (3,)
        ICRF axes, DE421's au and au/day, relative to ``centre``.
    centre : {"sun", "barycenter"}
        "sun": relative to the simulation's Sun; "barycenter": relative to the simulation's centre of
        mass (DE421's Solar-System barycentre to the centre-of-mass shift of the bodies left out).
    bodies, integrator
        As :func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421`.
    extra_forces : bool
        EIH 1PN + Earth J2 (default True).
    non_gravitational : dict, optional
        ``{"A1": …, "A2": …, "A3": …}`` in DE421 au/day² at 1 au (g(r) = (1 au/r)²); missing keys are 0.
        Needs ``extra_forces``.

    Returns
    -------
    rebound.Simulation
        At ``epoch``, with the body as the last particle.
    """
    if centre not in CENTRES:
        raise ValueError(f"centre expects one of {CENTRES}; got {centre!r}.")
    if non_gravitational and not extra_forces:
        raise ValueError("non_gravitational terms need extra_forces=True (they live in the same compiled force); "
                         "pass non_gravitational=None for a run without the extra forces.")
    sim = simulation_from_de421(epoch, bodies=bodies, integrator=integrator)
    if extra_forces:
        install_extra_forces(sim)
    position = np.asarray(position_au, dtype=float)
    velocity = np.asarray(velocity_au_day, dtype=float)
    origin = sim.particles[body_index(sim, "sun")] if centre == "sun" else sim.com()
    sim.add(m=0.0, x=origin.x + position[0], y=origin.y + position[1], z=origin.z + position[2],
            vx=origin.vx + velocity[0], vy=origin.vy + velocity[1], vz=origin.vz + velocity[2], name=name)
    if non_gravitational:
        terms = {key: float(non_gravitational.get(key, 0.0)) for key in ("A1", "A2", "A3")}
        set_nongravitational(sim, name, terms["A1"], terms["A2"], terms["A3"])
    return sim
