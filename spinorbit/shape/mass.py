"""Mass properties of a constant-density shape, and the RigidBody it makes.

The kernels are exact for the polyhedron (:mod:`spinorbit.core.model.polyhedron`); this module puts
the units on: a density (kg/m³) or a total mass, vertices in km, moments in kg m². A shape model's
axes are rarely principal, so the record keeps the proper rotation from the shape's axes to the
principal axes (A ≤ B ≤ C on x, y, z) and the shape's vertices there (centred on the centre of mass):
torques and Stokes coefficients are computed on that principal shape.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.body import RigidBody
from spinorbit.core.errors import SpinorbitError, require_finite_result
from spinorbit.core.model.polyhedron import mass_properties, principal_frame, stokes_coefficients
from spinorbit.quantities import finite_result, value_in
from spinorbit.shape.mesh import Shape

__all__ = ["ShapeMassProperties", "shape_mass_properties", "rigid_body_from_shape", "principal_shape",
           "check_moments", "InertiaMismatchError"]

KM5_TO_M5 = 1e15
KM3_TO_M3 = 1e9


class InertiaMismatchError(SpinorbitError, ValueError):
    """Moments given for a body contradict the moments of its shape at constant density."""


@dataclass(frozen=True)
class ShapeMassProperties:
    """Mass properties of a shape at constant density (built by :func:`shape_mass_properties`).

    Attributes
    ----------
    volume : Quantity (km³)
    mass : Quantity (kg)
    density : Quantity (kg / m³)
    center_of_mass : Quantity (3,) (km), in the shape's axes
    inertia : Quantity (3, 3) (kg m²), about the centre of mass, in the shape's axes
    principal_moments : Quantity (3,) (kg m²), A ≤ B ≤ C
    to_principal : ndarray (3, 3)
        Proper rotation: principal components = to_principal @ (shape components − centre of mass).
    reference_radius : Quantity (km)
        R_ref of the Stokes coefficients: the largest vertex distance from the centre of mass.
    stokes_c, stokes_s : ndarray (5, 5)
        Unnormalised Stokes coefficients of degrees 0–4 about the centre of mass on the principal axes.
    """

    volume: u.Quantity
    mass: u.Quantity
    density: u.Quantity
    center_of_mass: u.Quantity
    inertia: u.Quantity
    principal_moments: u.Quantity
    to_principal: np.ndarray
    reference_radius: u.Quantity
    stokes_c: np.ndarray
    stokes_s: np.ndarray


@finite_result("shape_mass_properties", "the mass or moments (ρ L⁵) of a shape this large or dense overflow double precision")
def shape_mass_properties(shape: Shape, density=None, mass=None) -> ShapeMassProperties:
    """Volume, mass, centre of mass, inertia, principal frame and Stokes coefficients of a shape.

    Parameters
    ----------
    shape : Shape
    density : Quantity, optional
        Constant density (kg/m³ or any density unit).
    mass : Quantity, optional
        Total mass instead of the density (exactly one of the two).

    Raises
    ------
    ValueError
        Neither or both of density and mass, or a non-positive one.
    """
    if (density is None) == (mass is None):
        raise ValueError("shape_mass_properties: give exactly one of density (such as 2000 * u.kg / u.m**3) or mass "
                         f"(such as 5e10 * u.kg); got density={density!r}, mass={mass!r}.")
    volume_km3, center_km, inertia_per_density = mass_properties(shape.vertices_km, shape.faces)
    if density is not None:
        rho = value_in("density", density, u.kg / u.m**3, "2000 * u.kg / u.m**3", shape=())
    else:
        rho = value_in("mass", mass, u.kg, "5e10 * u.kg", shape=()) / (volume_km3 * KM3_TO_M3)
    if not rho > 0:
        raise ValueError(f"density and mass must be positive; got a density of {rho!r} kg/m³.")
    inertia = inertia_per_density * rho * KM5_TO_M5
    # Checked before the eigen-decomposition, which fails on inf with a LinAlgError that names nothing.
    require_finite_result(f"shape_mass_properties: the inertia tensor (ρ = {rho:.4g} kg/m³, volume "
                          f"{volume_km3:.4g} km³)", inertia, "ρ L⁵ overflows double precision")
    moments, rotation = principal_frame(inertia)
    principal_vertices = (shape.vertices_km - center_km) @ rotation.T
    radius = float(np.linalg.norm(principal_vertices, axis=1).max())
    stokes_c, stokes_s = stokes_coefficients(principal_vertices, shape.faces, radius, degree_max=4)
    return ShapeMassProperties(
        volume=volume_km3 * u.km**3, mass=rho * volume_km3 * KM3_TO_M3 * u.kg, density=rho * u.kg / u.m**3,
        center_of_mass=center_km * u.km, inertia=inertia * u.kg * u.m**2,
        principal_moments=moments * u.kg * u.m**2, to_principal=rotation, reference_radius=radius * u.km,
        stokes_c=stokes_c, stokes_s=stokes_s,
    )


def principal_shape(shape: Shape, properties: ShapeMassProperties) -> Shape:
    """The shape moved to its centre of mass and turned onto its principal axes (A ≤ B ≤ C on x, y, z)."""
    vertices = (shape.vertices_km - properties.center_of_mass.to_value(u.km)) @ properties.to_principal.T
    return Shape(vertices * u.km, shape.faces, name=shape.name)


@finite_result("rigid_body_from_shape", "the moments (ρ L⁵) of a shape this large or dense overflow double precision")
def rigid_body_from_shape(shape: Shape, density=None, mass=None, name=None) -> RigidBody:
    """The :class:`~spinorbit.RigidBody` of a constant-density shape, on its principal axes.

    The body's x, y, z are the principal axes of :func:`shape_mass_properties` (A ≤ B ≤ C); its
    radius is the Stokes reference radius. States given in the shape's own axes are turned with
    ``properties.to_principal``.

    Examples
    --------
    >>> import astropy.units as u
    >>> from spinorbit.shape import ellipsoid_shape, rigid_body_from_shape
    >>> body = rigid_body_from_shape(ellipsoid_shape([1.0, 0.8, 0.6] * u.km), density=2000 * u.kg / u.m**3)
    >>> body.principal_moments[0] < body.principal_moments[2]
    True
    """
    properties = shape_mass_properties(shape, density=density, mass=mass)
    return RigidBody(properties.principal_moments, mass=properties.mass, radius=properties.reference_radius,
                     name=name or shape.name)


def check_moments(body: RigidBody, properties: ShapeMassProperties, rtol=1e-6) -> None:
    """Refuse a body whose principal moments contradict its shape's at constant density.

    Parameters
    ----------
    body : RigidBody
        With moments in kg m² (or dimensionless ratios, compared after scaling both to C = 1).
    properties : ShapeMassProperties
    rtol : float
        Relative tolerance on each moment (1e-6 by default: shape moments are exact to rounding,
        published moments carry a few significant digits; pass their precision).

    Raises
    ------
    InertiaMismatchError
        A moment differs by more than ``rtol``; the message gives both sets and what to do.
    """
    given = np.array(body.principal_moments)
    shape_moments = properties.principal_moments.to_value(u.kg * u.m**2)
    if body.moment_unit == u.dimensionless_unscaled:
        given, shape_moments = given / given[2], shape_moments / shape_moments[2]
    else:
        given = given * body.moment_unit.to(u.kg * u.m**2)
    worst = float(np.max(np.abs(given / shape_moments - 1.0)))
    if worst > rtol:
        raise InertiaMismatchError(
            f"the body's principal moments {given.tolist()} differ from its shape's {shape_moments.tolist()} by "
            f"{worst:.3g} (relative), more than rtol = {rtol:g}. The shape is not of constant density, or the "
            "moments belong to another shape or scale: use rigid_body_from_shape, or pass the moments' precision.")
