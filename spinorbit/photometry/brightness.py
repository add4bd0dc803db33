"""The kernel's door: the disk-integrated brightness of a shape for given body-frame Sun and observer directions.

:func:`brightness` is what everything else in :mod:`spinorbit.photometry` is built on (lightcurves,
magnitudes, and the fitting of rotation states to brightness). It takes unit vectors in the body
frame and returns the brightness

    L(ŝ, ô) = ∫ S(μ₀, μ) dA   over the part of the surface that is lit and seen,

in km² (the shape's area unit; S is dimensionless), unnormalised, so that a ratio of two
brightnesses is exact and magnitudes differ by −2.5 log₁₀ of it. The flux at an observer at distance
Δ for an incident solar flux F☉ is F☉ (ϖ/4π) L/Δ² for a Lommel–Seeliger surface of single-scattering
albedo ϖ and F☉ (A_L/π) L/Δ² for a Lambert surface of albedo A_L (``docs/photometry.md``).

Shapes:

- a :class:`~spinorbit.shape.Shape` (facets): the facet sum of
  :mod:`spinorbit.core.photometry.scattering`; with self-shadowing and self-occlusion through the ray
  tracer (:mod:`spinorbit.core.photometry.visibility`) when the shape is non-convex, and without it,
  exactly, when it is convex (:func:`shadowing_decision` says which and why);
- an :class:`Ellipsoid`: the Lommel–Seeliger law in closed form (Muinonen & Lumme 2015), the other
  laws by the facet sum of its icosphere mesh.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.core.model.polyhedron import face_geometry
from spinorbit.core.model.shadowing import shadow_geometry
from spinorbit.core.photometry.ellipsoid import lommel_seeliger_ellipsoid
from spinorbit.core.photometry.scattering import DEFAULT_LAMBERT_WEIGHT, facet_sum, law_weights
from spinorbit.core.photometry.visibility import shadowed_facet_sum
from spinorbit.photometry.errors import InvalidDirectionsError, PhotometryError
from spinorbit.quantities import value_in
from spinorbit.shape.mesh import Shape, ellipsoid_shape

__all__ = ["Ellipsoid", "brightness", "shadowing_decision", "UNIT_TOLERANCE", "SHADOWING_CHOICES"]

#: How far from 1 a direction's length may be: a few thousand roundings of a normalised double, far below
#: any real error in a direction (1e-9 rad is 0.2 mas), so that a vector that was never normalised is caught.
UNIT_TOLERANCE = 1e-9
#: ``shadowing`` values: "auto" traces rays on non-convex shapes only; "none" never traces them.
SHADOWING_CHOICES = ("auto", "none")


@dataclass(frozen=True, eq=False)
class Ellipsoid:
    """A triaxial ellipsoid x²/a² + y²/b² + z²/c² = 1 in the body frame, for :func:`brightness`.

    Parameters
    ----------
    semi_axes : Quantity, shape (3,)
        a, b, c along the body axes x, y, z (length; a bare number is refused).
    subdivisions : int
        Icosphere level of the facet model used for the laws without a closed form (Lambert,
        Kaasalainen): 20·4^k facets, the error falling as 4^−k (``docs/photometry.md``); 5 (20 480 facets,
        3e-4 relative, 0.3 mmag) by default.
    """

    semi_axes: u.Quantity
    subdivisions: int = 5

    def __post_init__(self):
        axes = value_in("semi_axes", self.semi_axes, u.km, "[1.0, 0.8, 0.6] * u.km", shape=(3,))
        if np.any(axes <= 0):
            raise PhotometryError(f"semi_axes: expected three positive lengths; got {axes.tolist()} km.")
        object.__setattr__(self, "semi_axes", np.array(axes) * u.km)

    @property
    def semi_axes_km(self) -> np.ndarray:
        return self.semi_axes.to_value(u.km)

    def facets(self) -> Shape:
        """The facet model: :func:`spinorbit.shape.ellipsoid_shape` at :attr:`subdivisions`."""
        return ellipsoid_shape(self.semi_axes, self.subdivisions)


class _Prepared:
    """A shape's facet normals and areas and its ray-tracing geometry, computed once per shape and sample count."""

    def __init__(self, shape, shadow_samples):
        vertices = shape.vertices_km
        self.normals, self.areas, _ = face_geometry(vertices, shape.faces)
        self.geometry = shadow_geometry(vertices, shape.faces, shadow_samples)


#: id(shape) -> (weak reference to the shape, {shadow_samples: _Prepared}); Shapes hold arrays and do not hash.
_PREPARED: dict = {}
_ELLIPSOID_FACETS: dict = {}


def _prepared(shape, shadow_samples):
    # Shapes are immutable: a fit calls brightness thousands of times on one shape, which is prepared once.
    key = id(shape)
    entry = _PREPARED.get(key)
    if entry is None or entry[0]() is not shape:
        entry = (weakref.ref(shape), {})
        _PREPARED[key] = entry
        weakref.finalize(shape, _PREPARED.pop, key, None)
    if shadow_samples not in entry[1]:
        entry[1][shadow_samples] = _Prepared(shape, shadow_samples)
    return entry[1][shadow_samples]


def _facets_of(shape):
    if isinstance(shape, Ellipsoid):
        key = (tuple(shape.semi_axes_km), shape.subdivisions)
        if key not in _ELLIPSOID_FACETS:
            _ELLIPSOID_FACETS[key] = shape.facets()
        return _ELLIPSOID_FACETS[key]
    return shape


def _check_shape(shape):
    if not isinstance(shape, (Shape, Ellipsoid)):
        raise PhotometryError(f"shape: expected a spinorbit.shape.Shape (facets) or a spinorbit.photometry.Ellipsoid; "
                              f"got {type(shape).__name__}. Read one with spinorbit.shape.read_obj or build "
                              "Ellipsoid([a, b, c] * u.km).")


def _directions(name, values):
    if isinstance(values, u.Quantity):
        if values.unit.physical_type != "dimensionless":
            raise InvalidDirectionsError(f"{name}: expected dimensionless unit vectors; got a Quantity in {values.unit}.")
        values = values.to_value(u.dimensionless_unscaled)
    array = np.atleast_2d(np.asarray(values, dtype=float))
    if array.ndim != 2 or array.shape[1] != 3:
        raise InvalidDirectionsError(f"{name}: expected an (n, 3) array of body-frame unit vectors; got shape "
                                     f"{np.shape(values)}.")
    if not np.all(np.isfinite(array)):
        raise InvalidDirectionsError(f"{name}: expected finite unit vectors; got NaN or inf in row "
                                     f"{int(np.argmax(~np.isfinite(array).all(axis=1)))}.")
    error = np.abs(np.linalg.norm(array, axis=1) - 1.0)
    if np.any(error > UNIT_TOLERANCE):
        row = int(np.argmax(error))
        raise InvalidDirectionsError(f"{name}: expected unit vectors (length 1 within {UNIT_TOLERANCE:g}); row {row} has "
                                     f"length {np.linalg.norm(array[row]):.12g}. Divide by np.linalg.norm(v, axis=1)"
                                     "[:, None] first.")
    return np.ascontiguousarray(array)


def shadowing_decision(shape, shadowing="auto"):
    """Whether :func:`brightness` traces rays for ``shape``, and why, in one sentence.

    Returns
    -------
    traced : bool
    reason : str
    """
    _check_shape(shape)
    if shadowing not in SHADOWING_CHOICES:
        raise PhotometryError(f"shadowing: expected one of {SHADOWING_CHOICES}; got {shadowing!r}.")
    if isinstance(shape, Ellipsoid):
        return False, "shadowing skipped: an ellipsoid is convex, so no part of it can shadow or hide another"
    if shadowing == "none":
        return False, "shadowing off (shadowing='none'): facets count when they face the Sun and the observer"
    geometry = _prepared(shape, 1).geometry
    if geometry.convex:
        return False, ("shadowing skipped: the shape is convex (no vertex rises above any facet's plane), so no "
                       "facet can shadow or hide another and the facet sum is exact without rays")
    count = int(geometry.candidates.sum())
    return True, (f"shadowing traced: the shape is non-convex ({count} of {len(shape)} facets have a vertex above "
                  "their plane); their sample points count when the rays to the Sun and to the observer leave the body")


def brightness(shape, sun_directions, observer_directions, law="lommel-seeliger",
               lambert_weight=DEFAULT_LAMBERT_WEIGHT, shadowing="auto", shadow_samples=4):
    """Disk-integrated brightness L = ∫ S(μ₀, μ) dA for each pair of body-frame directions (module docstring).

    Parameters
    ----------
    shape : spinorbit.shape.Shape or Ellipsoid
        The body's surface in its body frame.
    sun_directions, observer_directions : array_like, shape (n, 3) or (3,)
        Unit vectors from the body's centre to the Sun and to the observer, in the body frame
        (dimensionless; length 1 within :data:`UNIT_TOLERANCE`).
    law : {"lommel-seeliger", "lambert", "kaasalainen"}
        S = μμ₀/(μ + μ₀), μμ₀, or μμ₀/(μ + μ₀) + c μμ₀ (Kaasalainen, Torppa & Muinonen 2001: their law
        without its phase factor).
    lambert_weight : float
        c of "kaasalainen" (0.1 in their paper); ignored by the other laws.
    shadowing : {"auto", "none"}
        "auto": rays are traced for a non-convex Shape, and skipped (exactly) for a convex one;
        "none": never (the facets facing both count whole).
    shadow_samples : int
        q: q² sample points per facet for the rays (1: the facet's centroid); the misclassified area
        falls as 1/q. Unused when no rays are traced.

    Returns
    -------
    Quantity, shape (n,), km²
        L; 0 where no part of the surface is both lit and seen (the magnitude functions refuse that).

    Raises
    ------
    InvalidDirectionsError
        Directions that are not (n, 3) finite unit vectors, or different counts of Sun and observer directions.
    PhotometryError
        An unknown law or shape type, or a bad Lambert weight or ``shadowing``.
    """
    _check_shape(shape)
    sun = _directions("sun_directions", sun_directions)
    observer = _directions("observer_directions", observer_directions)
    if sun.shape != observer.shape:
        raise InvalidDirectionsError(f"sun_directions and observer_directions: expected one observer direction per Sun "
                                     f"direction; got {sun.shape[0]} and {observer.shape[0]}.")
    try:
        w_ls, w_l = law_weights(law, lambert_weight)
    except ValueError as error:
        raise PhotometryError(str(error)) from None
    if isinstance(shape, Ellipsoid) and law == "lommel-seeliger":
        return lommel_seeliger_ellipsoid(shape.semi_axes_km, sun, observer) * u.km**2
    traced, _ = shadowing_decision(shape, shadowing)
    facets = _facets_of(shape)
    if traced:
        return shadowed_facet_sum(_prepared(facets, shadow_samples).geometry, sun, observer, w_ls, w_l) * u.km**2
    prepared = _prepared(facets, 1)
    return facet_sum(prepared.normals, prepared.areas, sun, observer, w_ls, w_l) * u.km**2
