"""The binary's barycentre on a Keplerian heliocentric orbit, with units: the Sun's tide on the pair.

The elements are the barycentre's about the Sun, on the binary's inertial axes (the axes of the
state's R and quaternions), osculating at the state's instant (t = 0 of the run). The Sun's μ is
astropy's ``constants.GM_sun`` (IAU 2015 nominal, 1.3271244e20 m³/s²); the orbit's μ adds the pair's
G M. What the tide does and what it leaves out: :mod:`spinorbit.core.binary.solar_tide`.
"""

from __future__ import annotations

from dataclasses import dataclass

from astropy import constants
from astropy import units as u

from spinorbit.core.model.perturbers import kepler_source
from spinorbit.quantities import value_in

#: G M_sun in SI (astropy, IAU 2015 nominal).
GM_SUN_SI = constants.GM_sun.si.value


@dataclass(frozen=True)
class HeliocentricOrbit:
    """Heliocentric Keplerian elements of the binary's barycentre at the run's start.

    Parameters
    ----------
    semi_major_axis : Quantity, length (> 0; an ellipse)
    eccentricity : float, 0 ≤ e < 1
    inclination, node, argument_of_pericentre, mean_anomaly : Quantity, angle
        On the binary's inertial axes; the mean anomaly at the state's instant.
    """

    semi_major_axis: u.Quantity
    eccentricity: float = 0.0
    inclination: u.Quantity = 0 * u.deg
    node: u.Quantity = 0 * u.deg
    argument_of_pericentre: u.Quantity = 0 * u.deg
    mean_anomaly: u.Quantity = 0 * u.deg

    def __post_init__(self):
        self._elements()  # a bare number or a wrong unit refused where it was given

    def _elements(self):
        """(a in m, e, inclination, node, argument of pericentre, mean anomaly in rad), checked."""
        a = value_in("semi_major_axis", self.semi_major_axis, u.m, "1.6444 * u.au", shape=())
        e = value_in("eccentricity", self.eccentricity, u.dimensionless_unscaled, "0.384", shape=())
        if not (a > 0 and 0 <= e < 1):
            raise ValueError(f"heliocentric orbit: expected a > 0 and 0 ≤ e < 1 (a bound orbit about the Sun), got "
                             f"a = {a} m, e = {e}.")
        angles = [value_in(name, value, u.rad, "10 * u.deg", shape=())
                  for name, value in (("inclination", self.inclination), ("node", self.node),
                                      ("argument_of_pericentre", self.argument_of_pericentre),
                                      ("mean_anomaly", self.mean_anomaly))]
        return (a, e, *angles)

    def source(self, binary_mass_kg, g_si):
        """The core's Kepler source of the Sun relative to the barycentre (SI; ``sign=-1``)."""
        a, e, *angles = self._elements()
        return kepler_source(GM_SUN_SI, a, e, *angles, epoch=0.0, mu_orbit=GM_SUN_SI + g_si * binary_mass_kg,
                             sign=-1.0)
