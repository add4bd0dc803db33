"""DART's period change over the published uncertainties: an ensemble of full-two-body runs.

A member is the published system of :mod:`spinorbit.data.dart` with its inputs drawn from their
published uncertainties, the system's mass refitted to the measured 11.921473 h each time, then the
impulse and 20 orbits (about 10 days) of the full two-body problem. Its outcome row is the period
change (the mean sidereal period after the impact minus 11.921473 h, :meth:`BinaryRun.mutual_orbit`)
and the post-impact state: eccentricity, apsidal precession, Dimorphos's largest libration and
whether its rotation left the principal axis.

The distributions (:func:`dart_parameters`), each with its source:

- separation 1.206 ± 0.035 km (Naidu et al. 2024), Didymos's radii 394 ± 11 and 290 ± 16 m
  (Naidu et al. 2024), Dimorphos's extents 177 ± 2, 174 ± 4, 116 ± 2 m (Daly et al. 2023), normal;
- with ``impulse="dv"`` (default): the along-track Δv −2.63 ± 0.06 mm/s (Naidu et al. 2024) or
  −2.70 ± 0.10 mm/s (``source="cheng"``, Cheng et al. 2023), normal, and Dimorphos's density uniform
  on 1.5 … 3.3 g/cm³, the range over which Cheng et al. 2023 give β (it is 2.4 ± 0.9 g/cm³, Daly et
  al. 2023; a normal of that width would reach zero);
- with ``impulse="beta"``: β = 3.61 (+0.19, −0.25) (Cheng et al. 2023), a normal of σ 0.22 (the mean
  of the two sides), at their density of 2.4 g/cm³, which that β assumes: Δv = β m U / M with DART's
  mass and speed (Cheng et al.'s eq. 1 with the ejecta's momentum along U);
- the impact geometry: the impulse's direction off the anti-along-track direction, uniform within
  ±``geometry`` degrees in the orbit plane (towards the radial) and out of it. The sources at hand
  quote no uncertainty for it, so the default ±10° is an assumption, not a published value. With
  ``impulse="dv"`` the along-track component stays the sampled Δv (it is what the period measured);
  with ``impulse="beta"`` the tilt takes its cosine off it.

Dimorphos's extents are sorted after drawing (177 and 174 m lie 1σ apart): its long axis is the one
toward Didymos.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.ensemble.errors import EnsembleError
from spinorbit.ensemble.samplers import Normal, Uniform, sample_parameters

__all__ = ["DART_OUTCOME_UNITS", "DartMember", "GEOMETRY_SPREAD", "dart_member", "dart_parameters"]

#: Units of the numeric outcome columns of a :class:`DartMember` (``Ensemble(..., outcome_units=...)``).
DART_OUTCOME_UNITS = {"period_change": u.min, "dv_along_track": u.mm / u.s, "dv_total": u.mm / u.s,
                      "apsidal_rate": u.deg / u.day, "mean_separation": u.m, "max_libration": u.deg,
                      "max_wobble": u.deg,
                      "didymos_mass": u.kg, "dimorphos_mass": u.kg}
#: Assumed half-width of the impulse direction's spread off anti-along-track (deg; module docstring).
GEOMETRY_SPREAD = 10.0


@dataclass(frozen=True)
class DartMember:
    """One member: the published system with these inputs, the impulse, and ``orbits`` orbits after it.

    Lengths in m, density in kg/m³, ``dv`` in m/s (along-track, negative against the motion) or ``beta``
    (then Δv = β m U / M, DART's m and U), angles in degrees.
    """

    separation: float
    didymos_radii: tuple
    dimorphos_extents: tuple
    density: float
    dv: float | None
    beta: float | None
    azimuth: float
    elevation: float
    orbits: int
    order: int

    def direction(self, state):
        """The impulse's unit direction on the inertial axes: anti-along-track, turned by azimuth towards
        the outward radial and by elevation towards the orbit normal."""
        r = state.separation.to_value(u.m)
        v = state.velocity.to_value(u.m / u.s)
        along, radial = v / np.linalg.norm(v), r / np.linalg.norm(r)
        normal = np.cross(radial, along)
        az, el = math.radians(self.azimuth), math.radians(self.elevation)
        return math.cos(el) * (-math.cos(az) * along + math.sin(az) * radial) + math.sin(el) * normal

    def outcome_row(self, at_days=None):
        """Period change (min), Δv along-track and total (mm/s), e, apsidal rate (deg/day), mean separation
        (m), max |libration| (deg), the share of output times Dimorphos is in SAM or LAM (by rounding or
        more), its largest E/E0 − 1 and wobble amplitude (deg; tumbling above 1°), and both masses (kg)."""
        from spinorbit.binary import momentum_impulse, propagate
        from spinorbit.data import dart

        if at_days is not None:
            raise EnsembleError("a DART member reports the period change over its run; it has no outcome at named "
                                "times (give at=None).")
        system = dart.dart_system(order=self.order, separation=self.separation * u.m,
                                  didymos_radii=list(self.didymos_radii) * u.m,
                                  dimorphos_extents=list(self.dimorphos_extents) * u.m,
                                  density=self.density * u.kg / u.m ** 3)
        state = dart.dart_state(system, self.separation * u.m)
        direction = self.direction(state)
        along = state.velocity.to_value(u.m / u.s) / np.linalg.norm(state.velocity.to_value(u.m / u.s))
        if self.beta is None:
            # the along-track component is the given Δv; the tilt adds the other components
            delta_v = -self.dv / float(-np.dot(direction, along)) * direction
        else:
            delta_v = momentum_impulse(dart.DART_MASS, direction * dart.DART_SPEED, self.beta,
                                       system.secondary.mass).to_value(u.m / u.s)
        period = dart.PERIOD_BEFORE.to_value(u.s)
        times = np.linspace(0.0, self.orbits * period, self.orbits * 40 + 1) * u.s
        run = propagate(state.with_velocity_change(delta_v * u.m / u.s), times, rtol=1e-12)
        orbit = run.mutual_orbit()
        tumbling, excess, _, _ = run.tumbling_summary()
        return {
            "period_change": float((orbit.sidereal_period - dart.PERIOD_BEFORE).to_value(u.min)),
            "dv_along_track": float(np.dot(delta_v, along) * 1e3), "dv_total": float(np.linalg.norm(delta_v) * 1e3),
            "eccentricity": float(orbit.eccentricity),
            "apsidal_rate": float(orbit.apsidal_rate.to_value(u.deg / u.day)),
            "mean_separation": float(orbit.mean_separation.to_value(u.m)),
            "max_libration": float(np.max(np.abs(run.libration().to_value(u.deg)))),
            "tumbling_fraction": float(tumbling), "energy_excess": float(excess),
            "max_wobble": float(np.max(run.secondary_wobble().to_value(u.deg))),
            "didymos_mass": float(system.primary.mass.to_value(u.kg)),
            "dimorphos_mass": float(system.secondary.mass.to_value(u.kg)),
        }


def dart_member(separation, didymos_equatorial, didymos_polar, dimorphos_x, dimorphos_y, dimorphos_z, density,
                azimuth=0 * u.deg, elevation=0 * u.deg, dv=None, beta=None, orbits=20, order=4):
    """One member from a row of :func:`dart_parameters` (Quantities; give exactly one of ``dv`` and ``beta``)."""
    if (dv is None) == (beta is None):
        raise EnsembleError(f"dart_member: give exactly one of dv (an along-track velocity change, e.g. -2.63 mm/s) and "
                            f"beta (e.g. 3.61); got dv={dv!r}, beta={beta!r}.")
    extents = sorted((float(x.to_value(u.m)) for x in (dimorphos_x, dimorphos_y, dimorphos_z)), reverse=True)
    return DartMember(float(separation.to_value(u.m)),
                      (float(didymos_equatorial.to_value(u.m)), float(didymos_polar.to_value(u.m))), tuple(extents),
                      float(density.to_value(u.kg / u.m ** 3)), None if dv is None else float(dv.to_value(u.m / u.s)),
                      None if beta is None else float(beta), float(azimuth.to_value(u.deg)),
                      float(elevation.to_value(u.deg)), int(orbits), int(order))


def dart_parameters(n, seed=None, impulse="dv", source="naidu", geometry=GEOMETRY_SPREAD, orbits=20, order=4):
    """``n`` members drawn from the published uncertainties (module docstring), one seed each.

    Parameters
    ----------
    impulse : {"dv", "beta"}
        Sample the along-track Δv, or β with DART's mass and speed.
    source : {"naidu", "cheng"}
        With ``impulse="dv"``: Naidu et al. 2024's −2.63 ± 0.06 or Cheng et al. 2023's −2.70 ± 0.10 mm/s.
    geometry : float
        Half-width (deg) of the impulse direction's uniform spread off anti-along-track, in and out of
        the orbit plane (0: exactly anti-along-track).
    orbits, order : int
        Orbits after the impact (≥ 10 for the period to 0.01 s, docs/binary.md) and mutual-potential order.
    """
    from spinorbit.data import dart

    if impulse not in ("dv", "beta") or source not in ("naidu", "cheng"):
        raise EnsembleError(f"dart_parameters expects impulse 'dv' or 'beta' and source 'naidu' or 'cheng'; got "
                            f"impulse={impulse!r}, source={source!r}.")
    if not (isinstance(geometry, (int, float)) and 0.0 <= geometry < 90.0):
        raise EnsembleError(f"geometry expects a half-width in degrees in [0, 90); got {geometry!r}.")
    radii, radii_sigma = dart.DIDYMOS_RADII, dart.DIDYMOS_RADII_SIGMA
    extents, extents_sigma = dart.DIMORPHOS_EXTENTS, dart.DIMORPHOS_EXTENTS_SIGMA
    angle = (lambda: Uniform(-geometry * u.deg, geometry * u.deg)) if geometry > 0 else (lambda: 0.0 * u.deg)
    shape = dict(separation=Normal(dart.SEPARATION, dart.SEPARATION_SIGMA),
                 didymos_equatorial=Normal(radii[0], radii_sigma[0]), didymos_polar=Normal(radii[1], radii_sigma[1]),
                 dimorphos_x=Normal(extents[0], extents_sigma[0]), dimorphos_y=Normal(extents[1], extents_sigma[1]),
                 dimorphos_z=Normal(extents[2], extents_sigma[2]))
    if impulse == "dv":
        dv, sigma = (dart.DV_NAIDU, dart.DV_NAIDU_SIGMA) if source == "naidu" else (dart.DV_CHENG, dart.DV_CHENG_SIGMA)
        kick = dict(density=Uniform(1.5 * u.g / u.cm ** 3, 3.3 * u.g / u.cm ** 3), dv=Normal(dv, sigma))
    else:
        sigma = 0.5 * (dart.BETA_CHENG_PLUS + dart.BETA_CHENG_MINUS)
        kick = dict(density=dart.DENSITY, beta=Normal(dart.BETA_CHENG, sigma))
    return sample_parameters(n, seed, **shape, **kick, azimuth=angle(), elevation=angle(), orbits=int(orbits),
                             order=int(order))
