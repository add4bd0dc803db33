"""The Yarkovsky drift of a spherical asteroid's semi-major axis, with units: the linear theory.

The kernels are :mod:`spinorbit.core.model.yarkovsky` (Vokrouhlický 1998, 1999; Bottke et al. 2006,
eqs. 3–4; the κ functions as in Fenucci et al. 2021, eq. A.7). This module checks the Quantities
once, converts them to SI and puts au/Myr back on the drifts::

    import astropy.units as u
    from spinorbit.yarkovsky import yarkovsky_drift

    drift = yarkovsky_drift(radius=250 * u.m, density=2000 * u.kg / u.m**3, thermal_inertia=300 * u.J / (u.m**2 * u.K * u.s**0.5),
                            heat_capacity=680 * u.J / (u.kg * u.K), rotation_period=5 * u.h, obliquity=30 * u.deg,
                            semi_major_axis=1.2 * u.au, eccentricity=0.1)
    drift.total, drift.diurnal, drift.seasonal      # au / Myr;  drift.total.to(u.m / u.yr)

A circular orbit uses the closed forms; e > 0 averages the theory's acceleration field over the Kepler
orbit with Gauss's equation (:func:`spinorbit.core.model.yarkovsky.orbit_mean_drift`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.core.model import yarkovsky as kernel
from spinorbit.quantities import finite_result, value_in

__all__ = ["YarkovskyDrift", "yarkovsky_drift", "DRIFT_UNIT"]

#: The unit of the returned drifts.
DRIFT_UNIT = u.au / u.Myr
INERTIA_UNIT = u.J / (u.m**2 * u.K * u.s**0.5)
CONDUCTIVITY_UNIT = u.W / (u.m * u.K)
HEAT_CAPACITY_UNIT = u.J / (u.kg * u.K)
DENSITY_UNIT = u.kg / u.m**3


@dataclass(frozen=True)
class YarkovskyDrift:
    """da/dt of the linear theory: the diurnal and the seasonal parts and their sum, in au/Myr."""

    diurnal: u.Quantity
    seasonal: u.Quantity
    total: u.Quantity


def _positive(name, value, unit, example):
    number = value_in(name, value, unit, example, shape=())
    if not number > 0.0:
        raise ValueError(f"{name}: expected a positive Quantity such as {example}; got {value!s}. Give the physical "
                         "value (all sizes and material constants of the linear theory are > 0).")
    return number


def _unit_interval(name, value, low_closed, high_closed, meaning):
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected a finite number ({meaning}); got {value!r}.")
    # Any real number: Python's, numpy's (float32 too) or a dimensionless Quantity; NaN and inf refused.
    value = value_in(name, value, u.dimensionless_unscaled, "0.1", shape=())
    inside = (value >= 0.0 if low_closed else value > 0.0) and (value <= 1.0 if high_closed else value < 1.0)
    if not inside:
        interval = ("[" if low_closed else "(") + "0, 1" + ("]" if high_closed else ")")
        raise ValueError(f"{name}: expected a value in {interval} ({meaning}); got {value!r}.")
    return float(value)


@finite_result("yarkovsky_drift", "the linear theory's terms (R³, 1/a², exp of the penetration depths) overflow "
               "double precision for these values")
def yarkovsky_drift(*, radius, density, heat_capacity, rotation_period, obliquity, semi_major_axis,
                    eccentricity=0.0, thermal_inertia=None, conductivity=None, albedo=0.0, emissivity=0.9,
                    spin_longitude=0.0 * u.deg, samples=256) -> YarkovskyDrift:
    """da/dt of a homogeneous sphere from the linear theory (diurnal + seasonal).

    Parameters
    ----------
    radius, density, heat_capacity : Quantity
        Length, mass / volume, J / (kg K); all > 0.
    thermal_inertia, conductivity : Quantity
        Exactly one of them: Γ in J m⁻² K⁻¹ s⁻½, or K in W m⁻¹ K⁻¹ (Γ = √(Kρc)).
    rotation_period : Quantity
        Time > 0 (sidereal).
    obliquity : Quantity
        Angle between the spin axis and the orbit normal (0–180°; > 90° is retrograde).
    semi_major_axis : Quantity
        Length > 0.
    eccentricity : float
        0 ≤ e < 1.
    albedo : float
        Bond albedo, 0 ≤ A < 1 (the absorptivity is 1 − A).
    emissivity : float
        0 < ε ≤ 1.
    spin_longitude : Quantity
        Longitude of the spin axis' projection on the orbit plane from the perihelion (the seasonal
        part depends on it when e > 0).
    samples : int
        Points of the orbit average (e > 0).

    Returns
    -------
    YarkovskyDrift
        In au/Myr (``.to(u.m / u.yr)`` for metres per year).

    Raises
    ------
    QuantityInputError
        A wrong unit or a plain number where a Quantity is needed.
    ValueError
        A value outside its range, or both or neither of ``thermal_inertia`` and ``conductivity``.
    """
    radius_m = _positive("radius", radius, u.m, "250 * u.m")
    density_si = _positive("density", density, DENSITY_UNIT, "2000 * u.kg / u.m**3")
    capacity_si = _positive("heat_capacity", heat_capacity, HEAT_CAPACITY_UNIT, "680 * u.J / (u.kg * u.K)")
    period_s = _positive("rotation_period", rotation_period, u.s, "5 * u.h")
    distance_m = _positive("semi_major_axis", semi_major_axis, u.m, "1.2 * u.au")
    obliquity_rad = value_in("obliquity", obliquity, u.rad, "30 * u.deg", shape=())
    if not 0.0 <= obliquity_rad <= math.pi:
        raise ValueError(f"obliquity: expected an angle from 0 to 180 deg (spin axis to orbit normal); got {obliquity!s}.")
    longitude_rad = value_in("spin_longitude", spin_longitude, u.rad, "0 * u.deg", shape=())
    eccentricity = _unit_interval("eccentricity", eccentricity, True, False, "a bound orbit, 0 ≤ e < 1")
    albedo = _unit_interval("albedo", albedo, True, False, "the Bond albedo, 0 ≤ A < 1")
    emissivity = _unit_interval("emissivity", emissivity, False, True, "the emissivity, 0 < ε ≤ 1")
    if (thermal_inertia is None) == (conductivity is None):
        raise ValueError("give exactly one of thermal_inertia (e.g. 300 * u.J / (u.m**2 * u.K * u.s**0.5)) and "
                         f"conductivity (e.g. 0.01 * u.W / (u.m * u.K)); got thermal_inertia={thermal_inertia!s}, "
                         f"conductivity={conductivity!s}.")
    if conductivity is not None:
        conductivity_si = _positive("conductivity", conductivity, CONDUCTIVITY_UNIT, "0.01 * u.W / (u.m * u.K)")
    else:
        inertia = _positive("thermal_inertia", thermal_inertia, INERTIA_UNIT, "300 * u.J / (u.m**2 * u.K * u.s**0.5)")
        conductivity_si = inertia**2 / (density_si * capacity_si)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 16:
        raise ValueError(f"samples: expected an integer ≥ 16 (points of the orbit average); got {samples!r}.")
    material = dict(radius=radius_m, density=density_si, conductivity=conductivity_si, heat_capacity=capacity_si,
                    absorptivity=1.0 - albedo, emissivity=emissivity, spin_rate=2.0 * math.pi / period_s)
    if eccentricity == 0.0:
        diurnal, seasonal = kernel.circular_drift(obliquity=obliquity_rad, semi_major_axis=distance_m, **material)
    else:
        diurnal, seasonal = kernel.orbit_mean_drift(distance_m, eccentricity, obliquity_rad, longitude_rad,
                                                    samples=samples, **material)
    to_drift = (u.m / u.s).to(DRIFT_UNIT)
    return YarkovskyDrift(diurnal=diurnal * to_drift * DRIFT_UNIT, seasonal=seasonal * to_drift * DRIFT_UNIT,
                          total=(diurnal + seasonal) * to_drift * DRIFT_UNIT)
