"""Mirror planes of a shape on its principal axes: the symmetry that makes its mean YORP torque vanish.

A reflection σ that maps the surface onto itself pairs each facet (n, r, A) with a facet (σn, σr, A),
and r × n with σr × σn = −σ(r × n). So the recoil torque obeys T(σŝ) = −σ T(ŝ) (Rubincam 2000,
Icarus 148, 2, §4: a mirror-symmetric body has no YORP). For a rotation about an axis in the mirror
plane the average over the rotation phase meets ŝ and σŝ alike, and the spin component cancels. A
body mirror-symmetric in all three principal planes (a triaxial ellipsoid, a box) has, in the same way,
no mean torque along the spin and none that turns the obliquity, for any rotation about a principal
axis or any free tumble: its YORP (the mean change of S, Z, H) vanishes. A mean torque across the
plane of the spin and the orbit normal is left, which precesses the spin axis about the orbit normal
(tests/test_yorp_mean.py measures both).
"""

from __future__ import annotations

import numpy as np

from spinorbit.shape.mass import ShapeMassProperties
from spinorbit.shape.mesh import Shape

__all__ = ["mirror_planes", "MIRROR_RTOL"]

#: Agreement (relative to the shape's size, and to the largest facet area) asked of a reflected facet
#: and its partner: a generated mesh keeps its planes to rounding (1e-15), and the principal axes of a
#: symmetric shape come out of the eigensolver to ~1e-13; a random surface misses by its own scale.
MIRROR_RTOL = 1e-8


def mirror_planes(shape: Shape, properties: ShapeMassProperties, rtol=MIRROR_RTOL):
    """The principal axes (0, 1, 2 for A, B, C) whose normal plane through the centre of mass mirrors the surface.

    The recoil sees a flat piece of the surface only through its normal, its area and its centroid
    (Σ A r × n max(0, n·ŝ) over coplanar facets is that of the whole piece), so facets with one normal
    are merged first, and a box split along either diagonal of its faces counts as symmetric. Each
    piece's centroid, normal and area, reflected through the plane, must then meet a piece's within
    ``rtol`` (relative to the shape's largest extent and largest area).
    """
    from scipy.spatial import cKDTree

    from spinorbit.shape.thermal import principal_facets

    facet_normals, facet_areas, facet_centroids = principal_facets(shape, properties)
    _, first, piece = np.unique(np.round(facet_normals / rtol), axis=0, return_index=True, return_inverse=True)
    piece = piece.ravel()
    normals = facet_normals[first]
    areas = np.bincount(piece, weights=facet_areas)
    centroids = np.stack([np.bincount(piece, weights=facet_areas * facet_centroids[:, i]) for i in range(3)],
                         axis=1) / areas[:, None]
    size = float(np.abs(facet_centroids).max())
    tree = cKDTree(centroids / size)
    planes = []
    for axis in range(3):
        flip = np.ones(3)
        flip[axis] = -1.0
        distance, partner = tree.query(centroids * flip / size)
        if (np.all(distance <= rtol) and np.all(np.abs(normals[partner] - normals * flip) <= rtol)
                and np.all(np.abs(areas[partner] - areas) <= rtol * areas.max())):
            planes.append(axis)
    return tuple(planes)
