"""Sunlight's recoil on a shape, in the model units of the orbit-driven runs (au, day, kg m²).

The kernels are :mod:`spinorbit.core.model.thermal` (Rubincam's zero-conductivity Lambertian model
and its spherical-harmonic representation in the Sun's direction); this module measures the facets
of a :class:`~spinorbit.shape.Shape` on its principal axes about its centre of mass, in metres, and
scales the recoil pressure (N/m² at 1 au) to kg m² day⁻² per m³, so that the block's torque goes
straight into Euler's equations with moments in kg m² and times in days.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u

from spinorbit.core.model.polyhedron import face_geometry
from spinorbit.core.model.shadowing import shadow_geometry
from spinorbit.core.model.thermal import pack_thermal, recoil_pressure
from spinorbit.shape.mass import ShapeMassProperties
from spinorbit.shape.mesh import Shape

__all__ = ["thermal_block", "principal_facets", "principal_vertices", "DEFAULT_THERMAL_DEGREE", "DEFAULT_SHADOW_SAMPLES",
           "TORQUES"]

#: Degree of the default representation: its spin-averaged torque's error against the facet sum and
#: its cost per evaluation, degree by degree, are in docs/thermal.md (benchmarks/thermal_validation.py).
DEFAULT_THERMAL_DEGREE = 8
#: Sample points per facet edge of a shadowed fit (q² rays per facet and direction): the centroid
#: alone (q = 1) decides a facet's shadow all or nothing; q = 2 halves that step at four times the rays.
DEFAULT_SHADOW_SAMPLES = 2
#: How a block's torque is evaluated: the degree-L harmonics, or the facet sum itself (exact, one pass over
#: the facets per evaluation).
TORQUES = ("harmonics", "facets")
SECONDS_PER_DAY = 86400.0
METRES_PER_KM = 1000.0


def principal_vertices(shape: Shape, properties: ShapeMassProperties):
    """Vertex positions (m) on the principal axes about the centre of mass."""
    vertices = (shape.vertices_km - properties.center_of_mass.to_value(u.km)) @ properties.to_principal.T
    return vertices * METRES_PER_KM


def principal_facets(shape: Shape, properties: ShapeMassProperties):
    """Unit normals, areas (m²) and centroids (m) of the facets on the principal axes about the centre of mass."""
    normals, areas, centroids = face_geometry(principal_vertices(shape, properties), shape.faces)
    return normals, areas, centroids


def thermal_block(shape: Shape, properties: ShapeMassProperties, degree=DEFAULT_THERMAL_DEGREE, efficiency=1.0, *,
                  self_shadowing=False, shadow_samples=DEFAULT_SHADOW_SAMPLES, shadow_grid=None, torque="harmonics"):
    """The thermal block of a shape for ``make_model(..., thermal=block)`` in au, day and kg m².

    Parameters
    ----------
    shape : Shape
    properties : ShapeMassProperties
        Of the same shape (its principal frame and centre of mass).
    degree : int
        Degree L of the representation in the Sun's direction.
    efficiency : float
        η of :func:`spinorbit.core.model.thermal.recoil_pressure` (1: everything re-emitted or
        scattered Lambertian).
    self_shadowing : bool
        Count only the lit share of each facet (:mod:`spinorbit.core.model.shadowing`); the shadows
        are fitted into the representation once (an evaluation costs what one of the same degree with
        odd degrees present costs; docs/thermal.md). A convex shape is
        detected and gets the unshadowed block unchanged.
    shadow_samples : int
        q: q² shadow rays per facet and Sun direction (1: the centroid).
    shadow_grid : int, optional
        Latitudes of the fit's Sun-direction grid (default
        :func:`spinorbit.core.model.thermal.default_shadow_grid`).
    torque : {"harmonics", "facets"}
        What an evaluation sums: the degree-L representation, or the facets themselves (exact, not with
        self-shadowing; docs/thermal.md times both). The block carries the facets either way, for the
        exact mean YORP average.

    Returns
    -------
    ndarray
        Torque in kg m² / day² for the Sun's body-frame position in au.
    """
    if not 0.0 < efficiency <= 1.0:
        raise ValueError(f"efficiency: expected 0 < η ≤ 1 (the Lambertian share of the sunlight); got {efficiency!r}.")
    if not isinstance(self_shadowing, (bool, np.bool_)):
        raise TypeError(f"self_shadowing: expected True or False; got {self_shadowing!r}.")
    if torque not in TORQUES:
        raise ValueError(f"torque: expected one of {TORQUES}; got {torque!r}.")
    vertices = principal_vertices(shape, properties)
    normals, areas, centroids = face_geometry(vertices, shape.faces)
    shadowing = shadow_geometry(vertices, shape.faces, shadow_samples) if self_shadowing else None
    pressure_model = recoil_pressure(efficiency) * SECONDS_PER_DAY**2  # kg m⁻¹ s⁻² → kg m⁻¹ day⁻²
    return pack_thermal(normals, areas, centroids, int(degree), pressure_model, 1.0, shadowing=shadowing,
                        shadow_grid=shadow_grid, direct=torque == "facets")
