"""Shape models: closed triangulated surfaces read from OBJ and ICQ files or generated, and their mass properties.

The layer between the core's polyhedron kernels (:mod:`spinorbit.core.model.polyhedron`, plain
floats) and the rest of the package: a :class:`Shape` with a length unit, checked once; the readers
and writers of :mod:`spinorbit.shape.files`; the generated shapes of :mod:`spinorbit.shape.mesh`; and
the constant-density mass properties and :class:`~spinorbit.RigidBody` of :mod:`spinorbit.shape.mass`;
and sunlight's recoil torque in model units, :mod:`spinorbit.shape.thermal`.
"""

from spinorbit.core.model.polyhedron import InvalidMeshError
from spinorbit.shape.files import ShapeFileError, icq_grid, icq_mesh, read_icq, read_obj, write_icq, write_obj
from spinorbit.shape.mass import (
    InertiaMismatchError,
    ShapeMassProperties,
    check_moments,
    principal_shape,
    rigid_body_from_shape,
    shape_mass_properties,
)
from spinorbit.shape.mesh import Shape, box_shape, ellipsoid_shape, gaussian_random_sphere, icosphere, voxel_shape
from spinorbit.shape.thermal import principal_facets, principal_vertices, thermal_block

__all__ = [
    "Shape", "InvalidMeshError", "ShapeFileError", "InertiaMismatchError", "ShapeMassProperties",
    "read_obj", "write_obj", "read_icq", "write_icq", "icq_grid", "icq_mesh",
    "box_shape", "ellipsoid_shape", "gaussian_random_sphere", "icosphere", "voxel_shape",
    "shape_mass_properties", "rigid_body_from_shape", "principal_shape", "check_moments",
    "thermal_block", "principal_facets", "principal_vertices",
]
