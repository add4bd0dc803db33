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
from spinorbit.core.model.thermal import pack_thermal, recoil_pressure
from spinorbit.shape.mass import ShapeMassProperties
from spinorbit.shape.mesh import Shape

__all__ = ["thermal_block", "principal_facets", "DEFAULT_THERMAL_DEGREE"]

#: Degree of the default representation: its spin-averaged torque's error against the facet sum and
#: its cost per evaluation, degree by degree, are in docs/thermal.md (benchmarks/thermal_validation.py).
DEFAULT_THERMAL_DEGREE = 8
SECONDS_PER_DAY = 86400.0
METRES_PER_KM = 1000.0


def principal_facets(shape: Shape, properties: ShapeMassProperties):
    """Unit normals, areas (m²) and centroids (m) of the facets on the principal axes about the centre of mass."""
    vertices = (shape.vertices_km - properties.center_of_mass.to_value(u.km)) @ properties.to_principal.T
    normals, areas, centroids = face_geometry(vertices * METRES_PER_KM, shape.faces)
    return normals, areas, centroids


def thermal_block(shape: Shape, properties: ShapeMassProperties, degree=DEFAULT_THERMAL_DEGREE, efficiency=1.0):
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

    Returns
    -------
    ndarray
        Torque in kg m² / day² for the Sun's body-frame position in au.
    """
    if not 0.0 < efficiency <= 1.0:
        raise ValueError(f"efficiency: expected 0 < η ≤ 1 (the Lambertian share of the sunlight); got {efficiency!r}.")
    normals, areas, centroids = principal_facets(shape, properties)
    pressure_model = recoil_pressure(efficiency) * SECONDS_PER_DAY**2  # kg m⁻¹ s⁻² → kg m⁻¹ day⁻²
    return pack_thermal(normals, areas, centroids, int(degree), pressure_model, 1.0)
