"""(65803) Didymos and Dimorphos: the example case of a published full-two-body code, with units.

Source of every number: ``../shared/data/didymos_gubas_case.json`` (the example configuration of
GUBAS, Davis & Scheeres, the pre-DART design reference; Agrusa et al. 2020, Icarus 349, 113849 for
the benchmark), read once and copied here with its key next to each value:

- density 2.2031 g/cm³ (``density_g_cm3``), for both bodies;
- Dimorphos a triaxial ellipsoid, semi-axes 103.16, 79.35, 66.13 m (``secondary.semi_axes_m``),
  synchronous, long axis toward the primary (``secondary.state``), spin 1.464202e-4 rad/s (11.920 h);
- Didymos spin 7.72270e-4 rad/s (2.260 h) (``primary.spin_rad_s``), a sphere as the usual stand-in
  for its radar shape (``primary.shape``);
- separation 1.18–1.20 km (``separation_km``) and relative speed 0.17570 m/s (``relative_speed_m_s``);
  mutual-potential order 4 (``mutual_potential_order``).

**One number of the file is not used.** Its primary equal-volume radius, 576.7195 m, does not fit its
own orbit: with the density above it gives G(m_A + m_B) = 118.5 m³/s², a circular speed of 0.314 m/s at
1.20 km and a 6.67 h period, against the file's 0.17570 m/s and the 11.92 h of a synchronous
Dimorphos spinning at 1.464202e-4 rad/s (the published ~11.92 h pre-impact period). The speed, the
separation and the secondary's spin agree with each other (2π · 1200 m / 0.17570 m/s = 11.92 h), so
the primary's mass is taken from them: G(m_A + m_B) = v² R at R = 1.20 km, the circular orbit of
point masses, which gives m_A = 5.500e11 kg and an equal-volume radius of 390.6 m at the file's
density (close to the ~390 m of Didymos's published 780 m diameter). The file's radius is kept as
:data:`FILE_PRIMARY_RADIUS` so the discrepancy stays visible.
"""

from __future__ import annotations

import math

from astropy import units as u

from spinorbit.binary.system import G_SI, BinaryState, BinarySystem, Figure

#: ``density_g_cm3``
DENSITY = 2.2031 * u.g / u.cm ** 3
#: ``secondary.semi_axes_m``
DIMORPHOS_SEMI_AXES = [103.16, 79.35, 66.13] * u.m
#: ``secondary.spin_rad_s`` (synchronous: 11.920 h)
DIMORPHOS_SPIN = 1.464202e-4 * u.rad / u.s
#: ``primary.spin_rad_s`` (2.260 h)
DIDYMOS_SPIN = 7.72270e-4 * u.rad / u.s
#: ``separation_km``: the upper end, the one that agrees with the relative speed and the 11.92 h period
SEPARATION = 1.20 * u.km
#: ``relative_speed_m_s``
RELATIVE_SPEED = 0.17570 * u.m / u.s
#: ``mutual_potential_order``
ORDER = 4
#: ``primary.equal_volume_radius_m``: inconsistent with the orbit (module docstring), not used.
FILE_PRIMARY_RADIUS = 576.7195 * u.m

#: DART's impact for the GUBAS case's examples (the published system and ``spinorbit didymos`` take theirs
#: from :mod:`spinorbit.data.dart`); recalled, not from the shared data:
#: impactor mass 579.4 kg and speed 6.1449 km/s (Daly et al. 2023, Nature 616, 443), momentum
#: enhancement β = 3.61 (Cheng et al. 2023, Nature 616, 457, for a Dimorphos density of 2.4 g/cm³).
DART_MASS = 579.4 * u.kg
DART_SPEED = 6.1449 * u.km / u.s
DART_BETA = 3.61


def didymos_primary_radius():
    """Equal-volume radius of Didymos from the orbit (module docstring): G(m_A + m_B) = v² R."""
    secondary = Figure.ellipsoid("Dimorphos", DIMORPHOS_SEMI_AXES, DENSITY)
    total_mass = (RELATIVE_SPEED ** 2 * SEPARATION).to_value(u.m ** 3 / u.s ** 2) / G_SI
    primary_mass = total_mass - secondary.mass.to_value(u.kg)
    rho = DENSITY.to_value(u.kg / u.m ** 3)
    return (primary_mass / (rho * 4.0 / 3.0 * math.pi)) ** (1.0 / 3.0) * u.m


def didymos_system(order=ORDER):
    """Didymos (a sphere) and Dimorphos (the file's ellipsoid) at the file's density and ``order``."""
    primary = Figure.sphere("Didymos", didymos_primary_radius(), DENSITY)
    secondary = Figure.ellipsoid("Dimorphos", DIMORPHOS_SEMI_AXES, DENSITY)
    return BinarySystem(primary, secondary, order)


def didymos_state(order=ORDER, libration=0 * u.rad):
    """The file's initial state: 1.20 km, 0.17570 m/s, Dimorphos synchronous, Didymos at 2.260 h about z.

    Dimorphos spins at the file's 1.464202e-4 rad/s about its short axis; ``libration`` turns it from the
    line to Didymos (0: long axis exactly toward the primary).
    """
    state = BinaryState.synchronous(didymos_system(order), SEPARATION, DIDYMOS_SPIN, speed=RELATIVE_SPEED,
                                    libration=libration)
    return BinaryState(state.system, state.separation, state.velocity, state.primary_quaternion,
                       state.primary_spin, state.secondary_quaternion, [0.0, 0.0, DIMORPHOS_SPIN.value] * DIMORPHOS_SPIN.unit)
