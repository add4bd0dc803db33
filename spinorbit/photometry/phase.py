"""Phase functions and magnitudes: from a brightness L (km²) to reduced and apparent magnitudes.

The reduced magnitude (at 1 au from the Sun and the observer) of a body of brightness L(ŝ, ô) at
phase angle α is

    m_red = H − 2.5 log₁₀ [F(α) L(ŝ, ô) / L_ref],   L_ref = R² ℓ(0),

with R the radius of the sphere of the body's volume and ℓ(α) the same scattering law's brightness
of a unit sphere (``spinorbit.core.photometry.ellipsoid``). So **H is the reduced magnitude of the
equal-volume sphere at opposition**, and the shape enters through L/L_ref alone. The phase factor
F(α) is:

- :class:`HG1G2`: Φ(α) ℓ(0)/ℓ(α). The law's own geometric darkening of a sphere is divided out, so the
  equal-volume sphere's magnitude is exactly H − 2.5 log₁₀ Φ(α), the phase curve of sbpy's
  ``HG1G2`` (Muinonen et al. 2010), and a non-spherical body adds its lightcurve to it.
- :class:`LinearExponential`: f(α)/f(0), Kaasalainen et al. (2001)'s factor on the scattering law,
  normalised at opposition.

The apparent magnitude adds 5 log₁₀(r Δ / au²), with r and Δ the body's distances to the Sun and to
the observer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.core.model.polyhedron import mass_properties
from spinorbit.core.photometry.ellipsoid import lambert_sphere, lommel_seeliger_sphere
from spinorbit.core.photometry.phase_functions import hg1g2_phase, linear_exponential
from spinorbit.core.photometry.scattering import DEFAULT_LAMBERT_WEIGHT, law_weights
from spinorbit.photometry.brightness import Ellipsoid
from spinorbit.photometry.errors import PhotometryError
from spinorbit.quantities import QuantityInputError, value_in

__all__ = ["HG1G2", "LinearExponential", "NoLightError", "equal_volume_radius", "sphere_brightness",
           "reduced_magnitudes"]


class NoLightError(PhotometryError):
    """No part of the surface is both lit and seen (or the phase function is 0): the magnitude is infinite."""


def _magnitude(name, value):
    # A magnitude is dimensionless (-2.5 log10 of a flux ratio) and mag its one unit, so a bare number is
    # no guess: it is read in mag, as photometry writes it (docs/conventions.md, "Units").
    if not isinstance(value, u.Quantity):
        try:
            value = float(value) * u.mag
        except (TypeError, ValueError):
            raise QuantityInputError(f"{name} expects a magnitude such as 15.5 * u.mag or 15.5; got {value!r}.") from None
    return value_in(name, value, u.mag, "15.5 * u.mag", shape=())


@dataclass(frozen=True)
class HG1G2:
    """The H, G1, G2 phase function (Muinonen et al. 2010) as sbpy defines it.

    Parameters
    ----------
    H : Quantity
        Absolute magnitude of the equal-volume sphere (mag; plain numbers are read in mag).
    G1, G2 : float
        The basis weights, G1 ≥ 0, G2 ≥ 0, G1 + G2 ≤ 1.
    """

    H: u.Quantity
    G1: float
    G2: float

    def __post_init__(self):
        object.__setattr__(self, "H", _magnitude("H", self.H) * u.mag)
        g1, g2 = float(self.G1), float(self.G2)
        if not (g1 >= 0 and g2 >= 0 and g1 + g2 <= 1):
            raise PhotometryError(f"G1, G2: expected G1 ≥ 0, G2 ≥ 0 and G1 + G2 ≤ 1 (a phase function that never "
                                  f"turns negative); got G1 = {self.G1!r}, G2 = {self.G2!r}.")
        object.__setattr__(self, "G1", g1)
        object.__setattr__(self, "G2", g2)

    def phase_factor(self, phase_angle_rad, sphere_ratio):
        """F(α) = Φ(α) / [ℓ(α)/ℓ(0)] (module docstring); ``sphere_ratio`` = ℓ(α)/ℓ(0)."""
        phi = hg1g2_phase(phase_angle_rad, self.G1, self.G2)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(phi > 0, phi / sphere_ratio, 0.0)


@dataclass(frozen=True)
class LinearExponential:
    """Kaasalainen et al. (2001)'s phase factor f(α) = A₀ exp(−α/D) + kα + 1 on the scattering law.

    Parameters
    ----------
    H : Quantity
        Absolute magnitude of the equal-volume sphere (mag).
    amplitude : float
        A₀, the opposition surge's amplitude (≥ 0).
    width : Quantity
        D, its angular width (angle, > 0).
    slope : Quantity
        k, per angle (negative: the body darkens with phase), e.g. ``-0.5 / u.rad``.
    """

    H: u.Quantity
    amplitude: float = 0.5
    width: u.Quantity = 0.1 * u.rad
    slope: u.Quantity = -0.5 / u.rad

    def __post_init__(self):
        object.__setattr__(self, "H", _magnitude("H", self.H) * u.mag)
        width = value_in("width", self.width, u.rad, "0.1 * u.rad", shape=())
        slope = value_in("slope", self.slope, 1 / u.rad, "-0.5 / u.rad", shape=())
        amplitude = float(self.amplitude)
        if not (amplitude >= 0 and width > 0 and math.isfinite(amplitude)):
            raise PhotometryError(f"amplitude, width: expected A₀ ≥ 0 and D > 0; got A₀ = {self.amplitude!r}, "
                                  f"D = {self.width!r}.")
        object.__setattr__(self, "amplitude", amplitude)
        object.__setattr__(self, "width", width * u.rad)
        object.__setattr__(self, "slope", slope / u.rad)

    def phase_factor(self, phase_angle_rad, sphere_ratio):
        """F(α) = f(α)/f(0) (module docstring); ``sphere_ratio`` is not used."""
        parameters = (self.amplitude, self.width.to_value(u.rad), self.slope.to_value(1 / u.rad))
        return np.maximum(linear_exponential(phase_angle_rad, *parameters), 0.0) / linear_exponential(0.0, *parameters)


def equal_volume_radius(shape):
    """R (km) of the sphere of the shape's volume."""
    if isinstance(shape, Ellipsoid):
        return float(np.prod(shape.semi_axes_km)) ** (1.0 / 3.0)
    volume, _, _ = mass_properties(shape.vertices_km, shape.faces)
    return (3.0 * volume / (4.0 * math.pi)) ** (1.0 / 3.0)


def sphere_brightness(phase_angle_rad, law="lommel-seeliger", lambert_weight=DEFAULT_LAMBERT_WEIGHT):
    """ℓ(α): the law's brightness of a unit sphere, w_LS ℓ_LS(α) + w_L ℓ_L(α)."""
    w_ls, w_l = law_weights(law, lambert_weight)
    return w_ls * lommel_seeliger_sphere(phase_angle_rad) + w_l * lambert_sphere(phase_angle_rad)


def reduced_magnitudes(brightness_km2, phase_angle_rad, shape, phase_function, law="lommel-seeliger",
                       lambert_weight=DEFAULT_LAMBERT_WEIGHT, times=None):
    """m_red = H − 2.5 log₁₀[F(α) L / (R² ℓ(0))] (module docstring), in mag.

    Parameters
    ----------
    brightness_km2 : ndarray (n,)
        L from :func:`spinorbit.photometry.brightness` (km², as plain floats).
    phase_angle_rad : ndarray (n,)
    shape : Shape or Ellipsoid
        For R, the equal-volume radius.
    phase_function : HG1G2 or LinearExponential
    law, lambert_weight
        The law that gave L (its sphere normalises it).
    times : astropy.time.Time, optional
        Only to name the epochs in an error.

    Raises
    ------
    NoLightError
        Where F(α) L is 0: no facet faces both the Sun and the observer, or the phase function is 0.
    """
    if not isinstance(phase_function, (HG1G2, LinearExponential)):
        raise PhotometryError(f"phase_function: expected spinorbit.photometry.HG1G2 or LinearExponential; got "
                              f"{type(phase_function).__name__}.")
    alpha = np.asarray(phase_angle_rad, dtype=float)
    reference = sphere_brightness(0.0, law, lambert_weight)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = sphere_brightness(alpha, law, lambert_weight) / reference
    flux = phase_function.phase_factor(alpha, ratio) * np.asarray(brightness_km2) / (
        equal_volume_radius(shape) ** 2 * reference)
    dark = ~(flux > 0)
    if np.any(dark):
        where = np.nonzero(dark)[0]
        named = f" at {times[where[0]].iso}" if times is not None else ""
        raise NoLightError(f"{where.size} epoch(s) have no part of the surface both lit and seen (first: index "
                           f"{where[0]}{named}, phase angle {math.degrees(alpha[where[0]]):.2f} deg): the shape has no facet "
                           "facing the Sun and the observer there, so the magnitude is infinite. Drop those epochs.")
    return phase_function.H.to_value(u.mag) - 2.5 * np.log10(flux)
