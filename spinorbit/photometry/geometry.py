"""Where the Sun and the observer are, seen from the body: light-time corrected viewing geometry.

An observation at time t (the observer's clock) sees the body as it was at the emission time
t − τ, when it left the light that arrives at t. τ solves |R_body(t − τ) − R_obs(t)| = c τ
(barycentric ICRF positions). It is found by the fixed-point iteration τ ← |R_body(t − τ) − R_obs(t)|/c
from τ = 0: each step shrinks the error by v/c ≈ 1e-4, so three evaluations of the orbit leave
≲ 1e-9 s for a body within 30 au. The Sun's direction is taken at the emission time, from the body
to the Sun's centre. The Sun's own light time to the body, 8 min at 1 au, is left out: the Sun
moves about 0.01 km/s about the barycentre, so this moves the Sun's direction by 3e-8 rad.

The reverse question, which observation times see the body at given body times (the output times
of a :class:`~spinorbit.scene.Scene`), is :func:`observation_times`: t = t_e + τ with
τ = |R_body(t_e) − R_obs(t)|/c, iterated on the observer alone.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit.ephemeris import KNOWN_BODIES, barycentric_state_km, de421_constants, resolve_body
from spinorbit.photometry.errors import PhotometryError
from spinorbit.time import tdb_day_and_fraction

__all__ = ["SPEED_OF_LIGHT_KM_S", "LIGHT_TIME_ITERATIONS", "ViewingGeometry", "viewing_geometry",
           "observation_times", "observer_positions_km"]

#: c (km/s, exact by the SI definition of the metre).
SPEED_OF_LIGHT_KM_S = 299_792.458
#: Orbit evaluations of the light-time iteration: the error after k is ≈ τ (v/c)^k.
LIGHT_TIME_ITERATIONS = 3


class ViewingGeometry(NamedTuple):
    """The geometry of n observations (plain floats in ICRF; positions km, time s)."""

    observation_times: Time     #: t, as given
    emission_times: Time        #: t − τ (TDB)
    light_time_s: np.ndarray    #: τ
    sun_icrf: np.ndarray        #: (n, 3) unit vectors from the body to the Sun, at the emission time
    observer_icrf: np.ndarray   #: (n, 3) unit vectors from the body to the observer
    sun_distance_km: np.ndarray     #: r, body to Sun
    observer_distance_km: np.ndarray    #: Δ, body to observer

    @property
    def phase_angle_rad(self) -> np.ndarray:
        """α, the angle Sun–body–observer (atan2 of |ŝ × ô| and ŝ·ô: accurate near 0 and π)."""
        cross = np.linalg.norm(np.cross(self.sun_icrf, self.observer_icrf), axis=1)
        return np.arctan2(cross, np.einsum("ij,ij->i", self.sun_icrf, self.observer_icrf))


def _check_times(name, times):
    if not isinstance(times, Time):
        raise PhotometryError(f"{name}: expected an astropy Time (scalar or 1-D), such as Time(['2029-04-13T21:00'], "
                              f"scale='utc'); got {type(times).__name__}.")
    if times.ndim > 1:
        raise PhotometryError(f"{name}: expected a scalar or 1-D Time; got shape {times.shape}.")
    return times.reshape(-1)


def observer_positions_km(observer, times):
    """Barycentric ICRF positions (km, (n, 3)) of the observer at ``times``.

    ``observer`` is a DE421 body name (``"earth"``: the geocentre) or a barycentric ICRF position
    Quantity of shape (3,) or (n, 3) (a spacecraft's, at the observation times).
    """
    if isinstance(observer, str):
        try:
            name = resolve_body(observer)
        except (TypeError, ValueError):
            raise PhotometryError(f"observer: expected a DE421 body name ({', '.join(KNOWN_BODIES)}) or barycentric "
                                  f"ICRF positions as a length Quantity of shape (3,) or (n, 3); got {observer!r}."
                                  ) from None
        day, fraction = tdb_day_and_fraction(times)
        return np.asarray(barycentric_state_km(name, day, fraction)[0]).reshape(-1, 3)
    if not (isinstance(observer, u.Quantity) and observer.unit.physical_type == "length"):
        raise PhotometryError(f"observer: expected a DE421 body name or barycentric ICRF positions as a length Quantity "
                              f"of shape (3,) or (n, 3); got {type(observer).__name__}.")
    positions = np.atleast_2d(observer.to_value(u.km))
    if positions.shape not in ((1, 3), (len(times), 3)) or not np.all(np.isfinite(positions)):
        raise PhotometryError(f"observer: expected finite positions of shape (3,) or ({len(times)}, 3), one per "
                              f"observation; got shape {observer.shape}.")
    return np.broadcast_to(positions, (len(times), 3)).copy()


def _body_barycentric_km(orbit, times):
    """The body's barycentric ICRF position (km) at ``times``: its heliocentric state plus DE421's Sun."""
    au_km = de421_constants().au_km
    heliocentric = orbit.relative_state("sun", times)[0].to_value(u.au) * au_km
    day, fraction = tdb_day_and_fraction(times)
    return heliocentric + np.asarray(barycentric_state_km("sun", day, fraction)[0]).reshape(-1, 3)


def _sun_km(times):
    day, fraction = tdb_day_and_fraction(times)
    return np.asarray(barycentric_state_km("sun", day, fraction)[0]).reshape(-1, 3)


def _geometry(times, emission, tau, body, observer_km):
    to_sun, to_observer = _sun_km(emission) - body, observer_km - body
    r = np.linalg.norm(to_sun, axis=1)
    delta = np.linalg.norm(to_observer, axis=1)
    return ViewingGeometry(times, emission, tau, to_sun / r[:, None], to_observer / delta[:, None], r, delta)


def viewing_geometry(times, orbit, observer="earth"):
    """Light-time corrected geometry of observations made at ``times`` (module docstring).

    Parameters
    ----------
    times : astropy.time.Time
        Observation times (the observer's), scalar or 1-D, inside DE421's span.
    orbit : spinorbit.scene.Orbit
        The body's orbit (any kind: DE421, an ephemeris, a REBOUND run, elements or a state).
    observer : str or Quantity
        A DE421 body ("earth", the default: the geocentre) or barycentric ICRF positions (length,
        shape (3,) or (n, 3)).

    Returns
    -------
    ViewingGeometry

    Raises
    ------
    spinorbit.ephemeris.EphemerisRangeError
        A time (or its emission time) outside DE421's span.
    PhotometryError
        Times that are not a Time, or an observer that is neither a DE421 body nor positions.
    """
    times = _check_times("times", times)
    observer_km = observer_positions_km(observer, times)
    tdb = times.tdb
    tau = np.zeros(len(times))
    for _ in range(LIGHT_TIME_ITERATIONS):
        emission = tdb - tau * u.s
        body = _body_barycentric_km(orbit, emission)
        tau = np.linalg.norm(body - observer_km, axis=1) / SPEED_OF_LIGHT_KM_S
    # The last positions are those at the previous τ; they move by v δτ ≈ 1e-4 km from the final τ's.
    return _geometry(times, tdb - tau * u.s, tau, body, observer_km)


def observation_times(body_times, orbit, observer="earth"):
    """The geometry of observations that see the body at ``body_times`` (its emission times).

    For a lightcurve of a :class:`~spinorbit.scene.SceneResult`, whose attitudes are at the scene's
    output times: the observations are later by the light time (module docstring).

    Parameters
    ----------
    body_times : astropy.time.Time
        Emission times, scalar or 1-D.
    orbit, observer
        As :func:`viewing_geometry`.

    Returns
    -------
    ViewingGeometry
        ``observation_times`` are t_e + τ (TDB); ``emission_times`` are ``body_times``.
    """
    body_times = _check_times("body_times", body_times).tdb
    body = _body_barycentric_km(orbit, body_times)
    tau = np.zeros(len(body_times))
    for _ in range(LIGHT_TIME_ITERATIONS):
        observer_km = observer_positions_km(observer, body_times + tau * u.s)
        tau = np.linalg.norm(body - observer_km, axis=1) / SPEED_OF_LIGHT_KM_S
    return _geometry(body_times + tau * u.s, body_times, tau, body, observer_km)
