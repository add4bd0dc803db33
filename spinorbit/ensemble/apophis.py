"""The Apophis 2029 encounter as an ensemble: rotation phase × moment-ratio uncertainty.

The published spin state (Pravec et al. 2014) leaves the rotation phase at 2029 unknown, and its
moments are uncertain. A member here is the published SAM state (P_ψ = 263 h, P_φ = 27.38 h, angular
momentum towards ecliptic (250°, −75°); :mod:`spinorbit.data.asteroids`) of a body with moment ratios
``i1_i3 : i2_i3 : 1``, moved to the phase (``phase_psi``, ``phase_momentum``) of its free motion
(:func:`~spinorbit.ensemble.samplers.state_at_phase`), run through the encounter under the Sun's,
Earth's and Moon's degree-2 torques on the published orbit (REBOUND from the JPL#218 state, built
once per process and shared by the members of a chunk).

Moment ratios: the default ranges span the two published solutions in the project's sources
(see :mod:`spinorbit.data.asteroids`): Pravec et al. 2014, 0.61 : 0.965 : 1, and Lee et al. 2022,
0.64 : 0.97 : 1. They stand in for the formal uncertainties, which those sources do not quote.
"""

from __future__ import annotations

import functools

from astropy import units as u

from spinorbit.ensemble.samplers import Uniform, sample_parameters, state_at_phase

__all__ = ["I1_I3_RANGE", "I2_I3_RANGE", "apophis_member", "apophis_parameters", "encounter_orbit"]

#: I1/I3 and I2/I3 between Pravec et al. (2014) and Lee et al. (2022).
I1_I3_RANGE = (0.61, 0.64)
I2_I3_RANGE = (0.965, 0.97)


@functools.cache
def encounter_orbit(orbit="published"):
    """The Apophis orbit through 2029 as a Scene Orbit, built once per process (an N-body run from 2021)."""
    from spinorbit.data.asteroids import apophis_encounter_simulation
    from spinorbit.scene import Orbit

    return Orbit.rebound(apophis_encounter_simulation(orbit), "Apophis")


def apophis_member(phase_psi, phase_momentum, i1_i3, i2_i3, span_days=4.0, orbit="published",
                   perturbers=("sun", "earth", "moon"), tolerance_arcsec=1.0):
    """One member's Scene: from the published state's epoch to ``span_days / 2`` after the 2029 perigee."""
    from spinorbit.data.asteroids import APOPHIS_2029, APOPHIS_STATE_EPOCH, apophis_rotation_state
    from spinorbit.scene import Scene

    if isinstance(perturbers, str):  # a table column holds the names as one string
        perturbers = perturbers.split()
    state = state_at_phase(apophis_rotation_state(moment_ratios=(i1_i3, i2_i3)), phase_psi, phase_momentum)
    end = APOPHIS_2029.time_tdb + 0.5 * span_days * u.day
    return Scene(state, APOPHIS_STATE_EPOCH, end, perturbers=tuple(perturbers), orbit=encounter_orbit(orbit),
                 tolerance=tolerance_arcsec * u.arcsec)


def apophis_parameters(n, seed=None, span_days=4.0, orbit="published", perturbers=("sun", "earth", "moon"),
                       tolerance_arcsec=1.0, i1_i3=I1_I3_RANGE, i2_i3=I2_I3_RANGE):
    """``n`` members: both phases uniform on [0, 1), the moment ratios uniform on their ranges, one seed each."""
    return sample_parameters(n, seed, phase_psi=Uniform(0.0, 1.0), phase_momentum=Uniform(0.0, 1.0),
                             i1_i3=Uniform(*i1_i3), i2_i3=Uniform(*i2_i3), span_days=float(span_days), orbit=orbit,
                             perturbers=" ".join(perturbers), tolerance_arcsec=float(tolerance_arcsec))
