"""A lightcurve is a function of a body's attitudes: magnitudes at observation times, from a rotation state or a Scene.

:func:`lightcurve` puts the pieces together:

1. the light-time corrected geometry (:mod:`spinorbit.photometry.geometry`): for a
   :class:`~spinorbit.RotationState` the observation times are given and the body is seen at
   t − τ; for a :class:`~spinorbit.scene.SceneResult` the scene's output times are the body's
   (emission) times and the observations are at t_e + τ, so no attitude is ever interpolated;
2. the attitudes there (the exact free flow of the state, or the scene's rows), which turn the
   ICRF directions to the Sun and to the observer into the body frame;
3. :func:`spinorbit.photometry.brightness` of the shape, then the phase function's magnitudes
   (:mod:`spinorbit.photometry.phase`).

The table is an astropy ``TimeSeries``: ``time`` (the observation times), ``body_time`` (t − τ, TDB),
``light_time`` (s), ``magnitude`` (apparent), ``reduced_magnitude`` (at r = Δ = 1 au), ``brightness``
(L, km²), ``phase_angle``, ``aspect_angle`` (between the angular momentum and the direction to the
observer; for a principal-axis rotator the spin axis), ``solar_aspect_angle`` (the same to the Sun),
``observer_lon``, ``observer_lat``, ``sun_lon``, ``sun_lat`` (the directions in the body frame: the
sub-observer and subsolar points, deg), ``r`` and ``delta`` (au), ``sun_vector`` and ``observer_vector``
(from the body to the Sun at the body's time and to the observer, ICRF, au: what DAMIT's files hold). ``meta`` names the law, the phase
function, the observer and the shadowing decision with its reason.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u
from astropy.timeseries import TimeSeries

from spinorbit.core.photometry.scattering import DEFAULT_LAMBERT_WEIGHT
from spinorbit.ephemeris import de421_constants
from spinorbit.photometry.brightness import Ellipsoid, brightness, shadowing_decision
from spinorbit.photometry.errors import PhotometryError
from spinorbit.photometry.geometry import observation_times, viewing_geometry
from spinorbit.photometry.phase import HG1G2, reduced_magnitudes
from spinorbit.scene.scene import SceneResult
from spinorbit.state import RotationState

__all__ = ["ObserverInsideBodyError", "lightcurve", "body_frame", "body_to_icrf_matrices"]


class ObserverInsideBodyError(PhotometryError):
    """The observer is closer to the body's centre than the body's farthest surface point."""


def body_to_icrf_matrices(quaternions):
    """M(q) (n, 3, 3), body → ICRF, of scalar-first unit quaternions (n, 4) (``docs/conventions.md``)."""
    w, x, y, z = np.asarray(quaternions, dtype=float).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)


def body_frame(vectors_icrf, quaternions):
    """ICRF vectors (n, 3) in the body frame: Mᵀ v, renormalised (a unit vector stays one to rounding)."""
    turned = np.einsum("nji,nj->ni", body_to_icrf_matrices(quaternions), vectors_icrf)
    return turned / np.linalg.norm(turned, axis=1)[:, None]


def _angles_deg(vectors):
    return np.degrees(np.arctan2(vectors[:, 1], vectors[:, 0])) % 360.0, np.degrees(np.arcsin(np.clip(vectors[:, 2], -1, 1)))


def _separation_deg(a, b):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b)))


def _attitudes_of(source, times, orbit, observer):
    """(geometry, quaternions (n, 4), angular momentum directions (n, 3) ICRF) of a state or a scene result."""
    if isinstance(source, RotationState):
        if times is None:
            raise PhotometryError("times: a lightcurve of a RotationState needs the observation times (an astropy "
                                  "Time); a SceneResult brings its own.")
        if source.epoch is None:
            raise PhotometryError("source: the RotationState has no epoch, so its attitude at the observation times is "
                                  "undefined; build it with epoch=Time(...) or state.with_epoch(...).")
        geometry = viewing_geometry(times, orbit, observer)
        dt = (geometry.emission_times - source.epoch.tdb).to(u.day)
        quaternions, _ = source.propagate_torque_free(np.atleast_1d(dt))
        momentum = np.broadcast_to(source.angular_momentum_direction, (len(dt), 3))
        return geometry, np.asarray(quaternions).reshape(-1, 4), momentum
    if isinstance(source, SceneResult):
        if times is not None:
            raise PhotometryError("times: a SceneResult's output times are the body's times (the observations follow "
                                  "by the light time); leave times=None, or build the Scene at "
                                  "viewing_geometry(times, orbit).emission_times.")
        table = source.table
        geometry = observation_times(table["time"], orbit, observer)
        quaternions = np.stack([np.asarray(table[name], dtype=float) for name in ("q_w", "q_x", "q_y", "q_z")], axis=1)
        ra, dec = (table[name].to_value(u.rad) for name in ("pole_ra", "pole_dec"))
        momentum = np.stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)], axis=1)
        return geometry, quaternions, momentum
    raise PhotometryError(f"source: expected a spinorbit.RotationState or a spinorbit.scene.SceneResult; got "
                          f"{type(source).__name__}.")


def _outer_radius_km(shape):
    if isinstance(shape, Ellipsoid):
        return float(np.max(shape.semi_axes_km))
    return float(np.max(np.linalg.norm(shape.vertices_km, axis=1)))


def lightcurve(source, shape, orbit, times=None, observer="earth", phase_function=None, law="lommel-seeliger",
               lambert_weight=DEFAULT_LAMBERT_WEIGHT, shadowing="auto", shadow_samples=4):
    """Magnitudes of a rotating body as an observer sees them (module docstring).

    Parameters
    ----------
    source : RotationState or SceneResult
        The attitudes: a state with an epoch (propagated exactly, torque-free, to each emission
        time) or the rows of a Scene's run (its times are the emission times).
    shape : spinorbit.shape.Shape or Ellipsoid
        The surface, in the body axes of the state's attitude.
    orbit : spinorbit.scene.Orbit
        The body's orbit.
    times : astropy.time.Time, optional
        Observation times; required with a RotationState, refused with a SceneResult.
    observer : str or Quantity
        "earth" (default: the geocentre, DE421), another DE421 body, or barycentric ICRF positions
        (length, (3,) or (n, 3)).
    phase_function : HG1G2 or LinearExponential, optional
        Default: ``HG1G2(H=0 mag, G1=0.62, G2=0.14)``, which puts magnitudes relative to H.
    law, lambert_weight, shadowing, shadow_samples
        As :func:`spinorbit.photometry.brightness`.

    Returns
    -------
    astropy.timeseries.TimeSeries

    Raises
    ------
    ObserverInsideBodyError
        The observer within the body's outer radius of its centre.
    NoLightError
        An epoch where no facet faces both the Sun and the observer.
    spinorbit.ephemeris.EphemerisRangeError
        Times outside DE421's span.
    PhotometryError
        Anything else that is not as described here.
    """
    phase_function = HG1G2(0.0 * u.mag, 0.62, 0.14) if phase_function is None else phase_function
    traced, reason = shadowing_decision(shape, shadowing)
    geometry, quaternions, momentum = _attitudes_of(source, times, orbit, observer)
    outer = _outer_radius_km(shape)
    inside = geometry.observer_distance_km <= outer
    if np.any(inside):
        first = int(np.argmax(inside))
        raise ObserverInsideBodyError(
            f"observer: {geometry.observer_distance_km[first]:.6g} km from the body's centre at "
            f"{geometry.observation_times[first].iso}, inside its outer radius {outer:.6g} km; a disk-integrated "
            "brightness needs an observer outside the body. Check the observer's positions (km, barycentric ICRF).")
    sun_body = body_frame(geometry.sun_icrf, quaternions)
    observer_body = body_frame(geometry.observer_icrf, quaternions)
    values = brightness(shape, sun_body, observer_body, law=law, lambert_weight=lambert_weight, shadowing=shadowing,
                        shadow_samples=shadow_samples).to_value(u.km**2)
    alpha = geometry.phase_angle_rad
    reduced = reduced_magnitudes(values, alpha, shape, phase_function, law, lambert_weight, geometry.observation_times)
    au_km = de421_constants().au_km
    r_au, delta_au = geometry.sun_distance_km / au_km, geometry.observer_distance_km / au_km
    table = TimeSeries(time=geometry.observation_times)
    table["body_time"] = geometry.emission_times
    table["light_time"] = geometry.light_time_s * u.s
    table["magnitude"] = (reduced + 5.0 * np.log10(r_au * delta_au)) * u.mag
    table["reduced_magnitude"] = reduced * u.mag
    table["brightness"] = values * u.km**2
    table["phase_angle"] = np.degrees(alpha) * u.deg
    table["aspect_angle"] = _separation_deg(momentum, geometry.observer_icrf) * u.deg
    table["solar_aspect_angle"] = _separation_deg(momentum, geometry.sun_icrf) * u.deg
    for name, vectors in (("observer", observer_body), ("sun", sun_body)):
        lon, lat = _angles_deg(vectors)
        table[f"{name}_lon"], table[f"{name}_lat"] = lon * u.deg, lat * u.deg
    table["r"] = r_au * u.au
    table["delta"] = delta_au * u.au
    table["sun_vector"] = geometry.sun_icrf * r_au[:, None] * u.au
    table["observer_vector"] = geometry.observer_icrf * delta_au[:, None] * u.au
    table.meta.update(law=law, lambert_weight=lambert_weight if law == "kaasalainen" else None,
                      phase_function=repr(phase_function), observer=observer if isinstance(observer, str) else
                      "positions given", shadowing=reason, shadowing_traced=traced,
                      magnitudes="H is the reduced magnitude of the equal-volume sphere at opposition "
                                 "(docs/photometry.md)")
    return table
