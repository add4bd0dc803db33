"""(65803) Didymos–Dimorphos from the published values, before and after DART's impact.

Each number is the paper's, as compiled with its source in ``../shared/data/didymos_dart_published.json``:

- the pre-impact mutual period 11.921473 ± 0.000044 h and separation 1.206 ± 0.035 km, the orbit about
  circular (Naidu et al. 2024, PSJ 5, 74; Thomas et al. 2023, Nature 616, 448, from the DART team's
  pre-impact orbit solution);
- Didymos an oblate spheroid of equatorial radius 394 ± 11 m and polar radius 290 ± 16 m (Naidu et al.
  2024), spinning in 2.26 h about its short axis, the orbit's normal;
- Dimorphos's extents 177 × 174 × 116 m (± 2 × 4 × 2 m), a volume of (1.81 ± 0.18)e6 m³ (Daly et al.
  2023, Nature 616, 443), taken as the ellipsoid with those extents (semi-axes 88.5, 87, 58 m; its
  volume, 1.87e6 m³, is 3 % above the shape model's, inside the quoted error), synchronous, its long
  axis toward Didymos;
- the bulk density 2.4 ± 0.9 g/cm³ (Daly et al. 2023), here Dimorphos's (the density at which Cheng et
  al. 2023 quote β);
- DART's mass 579.4 kg and speed 6.1449 km/s relative to Dimorphos at impact (Cheng et al. 2023,
  Nature 616, 457, as the shared data compiles them);
- the along-track velocity change −2.70 ± 0.10 mm/s and β = 3.61 (+0.19, −0.25) (Cheng et al. 2023),
  −2.63 ± 0.06 mm/s (Naidu et al. 2024);
- the measured period change −33.0 ± 1.0 min (3σ; Thomas et al. 2023), of which −32.7 min ± 16 s right
  after the impact and −33.25 min ± 1.5 s in all after some weeks (Naidu et al. 2024); the
  post-impact apsidal precession 6.7 ± 0.2 °/day (Naidu et al. 2024) and eccentricity 0.028 ± 0.016
  (3σ; Scheirich et al. 2024, PSJ 5, 17).

**The system's mass is fitted, not taken from Kepler's law.** Didymos's oblateness and Dimorphos's
figure pull harder than two point masses, so at 1.206 km the measured period needs a GM 1.6 % below
Kepler's 4π² a³ / P². :func:`dart_system` finds Didymos's mass for which the full two-body model's
relative equilibrium (Dimorphos synchronous on a circular orbit, :meth:`BinarySystem.circular_speed`)
has the measured period; Dimorphos's mass is its ellipsoid's volume times its density. Didymos's
density then comes out near 2.9 g/cm³: Naidu et al.'s spheroid is the figure that fits the
dynamics and the images, smaller than Didymos's shape-model volume, so this density is not its bulk
density. Didymos's spin does not act on the orbit (a spheroid spinning about its axis has the same field at
every instant). :func:`reshaped` turns Dimorphos at the impact into Naidu et al.'s post-impact a/b ≈ 1.3,
a/c ≈ 1.6 (docs/binary.md, "The post-impact state against the papers").
"""

from __future__ import annotations

import math

import numpy as np
from astropy import units as u
from scipy.optimize import brentq

from spinorbit.binary.system import G_SI, BinaryState, BinarySystem, Figure
from spinorbit.quantities import value_in

__all__ = [
    "DART_MASS", "DART_SPEED", "DENSITY", "DENSITY_SIGMA", "DIDYMOS_RADII", "DIDYMOS_RADII_SIGMA",
    "DIDYMOS_SPIN_PERIOD", "DIMORPHOS_EXTENTS", "DIMORPHOS_EXTENTS_SIGMA", "DV_CHENG", "DV_CHENG_SIGMA", "DV_NAIDU",
    "DV_NAIDU_SIGMA", "BETA_CHENG", "BETA_CHENG_MINUS", "BETA_CHENG_PLUS", "ORDER", "PERIOD_BEFORE",
    "PERIOD_BEFORE_SIGMA", "PERIOD_CHANGE_INITIAL_NAIDU", "PERIOD_CHANGE_INITIAL_NAIDU_SIGMA", "PERIOD_CHANGE_THOMAS",
    "PERIOD_CHANGE_THOMAS_3SIGMA", "PERIOD_CHANGE_TOTAL_NAIDU", "PERIOD_CHANGE_TOTAL_NAIDU_SIGMA",
    "ECCENTRICITY_AFTER_SCHEIRICH", "ECCENTRICITY_AFTER_SCHEIRICH_3SIGMA", "APSIDAL_RATE_AFTER_NAIDU",
    "APSIDAL_RATE_AFTER_NAIDU_SIGMA", "DIMORPHOS_AXIS_RATIOS_AFTER", "SEPARATION", "SEPARATION_SIGMA", "along_track",
    "dart_state", "dart_system", "reshaped",
]

#: Pre-impact mutual orbit period and its 1σ (Naidu et al. 2024; ``pre_impact.mutual_orbit_period_h``).
PERIOD_BEFORE = 11.921473 * u.h
PERIOD_BEFORE_SIGMA = 0.000044 * u.h
#: Pre-impact separation (semimajor axis of the circular orbit) and its 1σ (``pre_impact.semimajor_axis_km``).
SEPARATION = 1.206 * u.km
SEPARATION_SIGMA = 0.035 * u.km
#: Didymos's equatorial and polar radii as an oblate spheroid, and their 1σ (Naidu et al. 2024).
DIDYMOS_RADII = [394.0, 290.0] * u.m
DIDYMOS_RADII_SIGMA = [11.0, 16.0] * u.m
#: Didymos's rotation period (``pre_impact.didymos_spin_period_h``); it does not act on the orbit.
DIDYMOS_SPIN_PERIOD = 2.26 * u.h
#: Dimorphos's extents (full lengths of its three axes) and their 1σ (Daly et al. 2023).
DIMORPHOS_EXTENTS = [177.0, 174.0, 116.0] * u.m
DIMORPHOS_EXTENTS_SIGMA = [2.0, 4.0, 2.0] * u.m
#: Bulk density and its 1σ (Daly et al. 2023), Dimorphos's here.
DENSITY = 2.4 * u.g / u.cm ** 3
DENSITY_SIGMA = 0.9 * u.g / u.cm ** 3
#: DART at impact: mass and speed relative to Dimorphos (Cheng et al. 2023, ``impact``).
DART_MASS = 579.4 * u.kg
DART_SPEED = 6.1449 * u.km / u.s
#: Along-track velocity change of Dimorphos and its 1σ: Cheng et al. 2023, Naidu et al. 2024.
DV_CHENG = -2.70 * u.mm / u.s
DV_CHENG_SIGMA = 0.10 * u.mm / u.s
DV_NAIDU = -2.63 * u.mm / u.s
DV_NAIDU_SIGMA = 0.06 * u.mm / u.s
#: Momentum enhancement for equal densities of 2400 kg/m³, with its 1σ range (Cheng et al. 2023).
BETA_CHENG = 3.61
BETA_CHENG_PLUS = 0.19
BETA_CHENG_MINUS = 0.25
#: Measured period change, 3σ (Thomas et al. 2023).
PERIOD_CHANGE_THOMAS = -33.0 * u.min
PERIOD_CHANGE_THOMAS_3SIGMA = 1.0 * u.min
#: Period change right after the impact and its 1σ (Naidu et al. 2024).
PERIOD_CHANGE_INITIAL_NAIDU = -32.7 * u.min
PERIOD_CHANGE_INITIAL_NAIDU_SIGMA = 16.0 * u.s
#: Period change after some weeks (reshaping and mass loss added ~34 s) and its 1σ (Naidu et al. 2024).
PERIOD_CHANGE_TOTAL_NAIDU = -33.25 * u.min
PERIOD_CHANGE_TOTAL_NAIDU_SIGMA = 1.5 * u.s
#: Post-impact apsidal precession rate and its 1σ (Naidu et al. 2024).
APSIDAL_RATE_AFTER_NAIDU = 6.7 * u.deg / u.day
APSIDAL_RATE_AFTER_NAIDU_SIGMA = 0.2 * u.deg / u.day
#: Post-impact eccentricity, 3σ (Scheirich et al. 2024).
ECCENTRICITY_AFTER_SCHEIRICH = 0.028
ECCENTRICITY_AFTER_SCHEIRICH_3SIGMA = 0.016
#: Dimorphos's axis ratios a/b and a/c after the impact, from the fitted C20 and C22 of a uniform
#: triaxial ellipsoid (Naidu et al. 2024, ``measured_outcome.post_impact_dimorphos_shape``).
DIMORPHOS_AXIS_RATIOS_AFTER = (1.3, 1.6)
#: Mutual-potential order: 4 carries Didymos's J4 and the two figures' coupling (order 2 changes the
#: period change by 0.08 min, docs/binary.md).
ORDER = 4


def _kepler_gm(separation_m, period_s):
    return 4.0 * math.pi ** 2 * separation_m ** 3 / period_s ** 2


def dart_system(order=ORDER, separation=SEPARATION, period=PERIOD_BEFORE, didymos_radii=DIDYMOS_RADII,
                dimorphos_extents=DIMORPHOS_EXTENTS, density=DENSITY):
    """Didymos (an oblate spheroid) and Dimorphos (an ellipsoid), Didymos's mass fitted to the period.

    Didymos's mass is the one for which Dimorphos, synchronous on a circular orbit at ``separation``,
    goes round in ``period`` in the full two-body model of this ``order`` (the relative equilibrium of
    :meth:`BinarySystem.circular_speed`, solved by Brent's method to 1e-14 of the density).

    Parameters
    ----------
    order : int
        Mutual-potential order, 0 … 4.
    separation : Quantity, length
        Pre-impact separation (default 1.206 km).
    period : Quantity, time
        Pre-impact mutual period (default 11.921473 h).
    didymos_radii : Quantity (2,), length
        Equatorial and polar radius of Didymos, equatorial ≥ polar (default 394, 290 m).
    dimorphos_extents : Quantity (3,), length
        Dimorphos's full extents, longest first (default 177, 174, 116 m).
    density : Quantity, mass density
        Dimorphos's density (default 2.4 g/cm³).

    Raises
    ------
    ValueError
        For radii or extents out of order or non-positive, or when no positive Didymos mass gives the
        period (Dimorphos alone would pull harder than the period allows).
    """
    r = value_in("separation", separation, u.m, "1.206 * u.km", shape=())
    p = value_in("period", period, u.s, "11.921473 * u.h", shape=())
    radii = value_in("didymos_radii", didymos_radii, u.m, "[394, 290] * u.m", shape=(2,))
    extents = value_in("dimorphos_extents", dimorphos_extents, u.m, "[177, 174, 116] * u.m", shape=(3,))
    if not (radii[0] >= radii[1] > 0):
        raise ValueError(f"didymos_radii: expected an oblate spheroid's equatorial ≥ polar radius > 0, got "
                         f"{radii.tolist()} m; give [equatorial, polar].")
    if not (r > 0 and p > 0):
        raise ValueError(f"separation, period: expected positive values, got {r} m and {p} s.")
    secondary = Figure.ellipsoid("Dimorphos", 0.5 * extents * u.m, density)
    volume = 4.0 / 3.0 * math.pi * radii[0] ** 2 * radii[1]

    def system(rho):
        primary = Figure.ellipsoid("Didymos", [radii[0], radii[0], radii[1]] * u.m, rho * u.kg / u.m ** 3)
        return BinarySystem(primary, secondary, order)

    def period_error(rho):
        return 2.0 * math.pi * r / system(rho).circular_speed(r * u.m).to_value(u.m / u.s) / p - 1.0

    kepler_mass = _kepler_gm(r, p) / G_SI - secondary.mass.to_value(u.kg)
    if not kepler_mass > 0:
        raise ValueError(f"dart_system: a period of {p / 3600:g} h at {r:g} m needs a total mass of "
                         f"{_kepler_gm(r, p) / G_SI:.4g} kg, less than Dimorphos's {secondary.mass.value:.4g} kg "
                         "alone; check the separation, the period and Dimorphos's density.")
    guess = kepler_mass / volume
    # The figures add to the point masses' pull by a few percent at most, so the root is within ±50 % of Kepler's.
    low, high = 0.5 * guess, 1.5 * guess
    if not period_error(low) > 0 > period_error(high):
        raise ValueError(f"dart_system: no Didymos density between {low:.4g} and {high:.4g} kg/m³ gives the period "
                         f"{p / 3600:g} h at {r:g} m in the order-{order} model; the figures' pull is far from the "
                         "point masses' (is the separation near contact?).")
    rho = brentq(period_error, low, high, xtol=1e-14 * guess, rtol=1e-15)
    return system(rho)


def dart_state(system=None, separation=SEPARATION, libration=0 * u.rad):
    """The pre-impact relative equilibrium: Dimorphos synchronous at ``separation`` on a circular orbit.

    Dimorphos at +x on the inertial x axis, moving along +y at the model's circular speed, its long axis
    toward Didymos and its spin the orbit's rate; Didymos spinning in 2.26 h about its axis, the orbit's
    normal (``BinaryState.synchronous``). ``system`` defaults to :func:`dart_system` at ``separation``;
    ``libration`` turns Dimorphos from the line to Didymos (a free libration before the impact).
    """
    system = dart_system(separation=separation) if system is None else system
    spin = 2.0 * math.pi / DIDYMOS_SPIN_PERIOD.to_value(u.s)
    return BinaryState.synchronous(system, separation, spin * u.rad / u.s, libration=libration)


def along_track(state, delta_v):
    """Dimorphos's velocity change ``delta_v`` (Quantity, velocity; negative: against the motion) along its
    orbital velocity in ``state``, as a (3,) Quantity on the inertial axes."""
    dv = value_in("delta_v", delta_v, u.m / u.s, "-2.63 * u.mm / u.s", shape=())
    velocity = state.velocity.to_value(u.m / u.s)
    return dv * velocity / np.linalg.norm(velocity) * u.m / u.s


def reshaped(state, axis_ratios=DIMORPHOS_AXIS_RATIOS_AFTER):
    """``state`` with Dimorphos reshaped at that instant to the axis ratios (a/b, a/c), mass and volume kept.

    The default ratios are Naidu et al. 2024's post-impact ones (1.3, 1.6). The reshaping is internal, so
    Dimorphos keeps its attitude and its rotational angular momentum: its spin becomes I'⁻¹ I ω (the
    moments change by a few percent). Didymos and the orbit are unchanged.
    """
    a_b, a_c = (float(r) for r in axis_ratios)
    if not (a_c >= a_b >= 1.0):
        raise ValueError(f"axis_ratios: expected a/b ≥ 1 and a/c ≥ a/b (semi-axes a ≥ b ≥ c), got {axis_ratios!r}.")
    system = state.system
    volume = float(np.prod(system.secondary.semi_axes_m))
    a = (volume * a_b * a_c) ** (1.0 / 3.0)
    axes = [a, a / a_b, a / a_c]
    mass = system.secondary.mass.to_value(u.kg)
    density = mass / (4.0 / 3.0 * math.pi * float(np.prod(axes)))
    figure = Figure.ellipsoid("Dimorphos, reshaped", axes * u.m, density * u.kg / u.m ** 3)
    spin = system.secondary.moments.value * state.secondary_spin.to_value(u.rad / u.s) / figure.moments.value
    return BinaryState(BinarySystem(system.primary, figure, system.order), state.separation, state.velocity,
                       state.primary_quaternion, state.primary_spin, state.secondary_quaternion, spin * u.rad / u.s)
