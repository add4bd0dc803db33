"""Members of the pickling tests: a tumbler 60 000 km from Earth on a REBOUND orbit with Earth's J2 and EIH.

The orbit is built once per process and cached in a module dict, as the issue's script did in
``__main__``; shipped by value (cloudpickle), the dict travels with ``member``, the Orbit in it too.
Earth's J2 moves this orbit measurably within a day, so a copy that lost the compiled extra forces
(REBOUND's own pickling) gives other torques and another spin.
"""

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.ephemeris import barycentric_state_au, de421_constants
from spinorbit.scene import Orbit, Scene

EPOCH = Time("2029-04-13T00:00:00", scale="tdb")
ORBITS = {}


def orbit():
    """The cached orbit: 60 000 km from Earth at 3.5 km/s across the line to it, among DE421's planets."""
    if "near earth" not in ORBITS:
        au_km = de421_constants().au_km
        day = EPOCH.tdb.jd1 - 2451545.0 + EPOCH.tdb.jd2
        earth_r, earth_v = barycentric_state_au("earth", day)
        position = (np.asarray(earth_r) + np.array([60000.0, 0.0, 0.0]) / au_km) * au_km * u.km
        velocity = (np.asarray(earth_v) + np.array([0.0, 3.5 * 86400.0, 0.0]) / au_km) * au_km * u.km / u.day
        ORBITS["near earth"] = Orbit.from_state(position, velocity, EPOCH, centre="barycenter", name="rock")
    return ORBITS["near earth"]


def member(phase):
    """One member: Apophis's moments, spin about the short axis turned by ``phase``, 0.5 d past Earth."""
    state = RotationState(RigidBody([0.61, 0.965, 1.0]), [np.cos(phase), 0.0, np.sin(phase), 0.0],
                          [0.3, 0.1, 2.0] * u.rad / u.day)
    return Scene(state, EPOCH, EPOCH + 0.5 * u.day, perturbers=("earth",), orbit=orbit(),
                 tolerance=0.01 * u.arcsec)


def run_table(scene):
    """``scene.run().table``: what a worker process sends back."""
    return scene.run().table
