"""Self-shadowing and self-occlusion in the facet sum: which parts of a facet are both lit and seen.

On a non-convex surface a facet that faces the Sun and the observer (μ₀ > 0, μ > 0) may be in
another part's shadow, or hidden behind another part. Each facet carries the q² sample points of
:func:`spinorbit.core.model.shadowing.subdivision_points`; a sample point counts when the ray towards
the Sun and the ray towards the observer both leave the body (:func:`~spinorbit.core.model.shadowing.ray_blocked`,
Möller & Trumbore 1997 through the bounding-volume hierarchy), and the facet contributes
A_k S(μ₀, μ) × (the share of its points that count)::

    L(ŝ, ô) = Σ_k A_k S(μ₀, μ) (1/q²) Σ_j lit_kj(ŝ) seen_kj(ô).

Only the facets some vertex rises above are ever tested (``ShadowGeometry.candidates``): the rest
can be neither shadowed nor hidden, and on a convex surface that is every facet, where this sum
equals :func:`spinorbit.core.photometry.scattering.facet_sum` and the caller uses that one instead.
A ray is followed only up to the height of the highest vertex above the facet's plane.
"""

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.model.shadowing import STACK_DEPTH, ray_blocked

__all__ = ["shadowed_facet_sum"]


@jit
def _shadowed_sum(vertices, faces, normals, areas, candidates, heights, points, box_low, box_high, children, leaf,
                  order, sun, observer, w_ls, w_l, out):
    stack = np.empty(STACK_DEPTH, dtype=np.int64)
    share = 1.0 / points.shape[0]
    for d in range(sun.shape[0]):
        sx, sy, sz = sun[d, 0], sun[d, 1], sun[d, 2]
        ox, oy, oz = observer[d, 0], observer[d, 1], observer[d, 2]
        total = 0.0
        for k in range(faces.shape[0]):
            nx, ny, nz = normals[k, 0], normals[k, 1], normals[k, 2]
            mu0 = nx * sx + ny * sy + nz * sz
            mu = nx * ox + ny * oy + nz * oz
            if mu0 <= 0.0 or mu <= 0.0:
                continue
            weight = areas[k] * mu * mu0 * (w_ls / (mu + mu0) + w_l)
            if not candidates[k]:
                total += weight
                continue
            a, b, c = faces[k, 0], faces[k, 1], faces[k, 2]
            # Nothing rises more than heights[k] above the facet's plane: a ray is done when it gets there.
            reach_sun, reach_observer = heights[k] / mu0, heights[k] / mu
            counted = 0
            for j in range(points.shape[0]):
                u, v = points[j, 0], points[j, 1]
                px = vertices[a, 0] + u * (vertices[b, 0] - vertices[a, 0]) + v * (vertices[c, 0] - vertices[a, 0])
                py = vertices[a, 1] + u * (vertices[b, 1] - vertices[a, 1]) + v * (vertices[c, 1] - vertices[a, 1])
                pz = vertices[a, 2] + u * (vertices[b, 2] - vertices[a, 2]) + v * (vertices[c, 2] - vertices[a, 2])
                if ray_blocked(px, py, pz, sx, sy, sz, reach_sun, k, vertices, faces, box_low, box_high, children,
                               leaf, order, stack):
                    continue
                if ray_blocked(px, py, pz, ox, oy, oz, reach_observer, k, vertices, faces, box_low, box_high,
                               children, leaf, order, stack):
                    continue
                counted += 1
            total += weight * counted * share
        out[d] = total


def shadowed_facet_sum(geometry, sun_directions, observer_directions, w_ls, w_l):
    """The facet sum with self-shadowing and self-occlusion (module docstring) for each epoch.

    Parameters
    ----------
    geometry : spinorbit.core.model.shadowing.ShadowGeometry
        The surface prepared for rays (:func:`~spinorbit.core.model.shadowing.shadow_geometry`), with
        its q² sample points per facet.
    sun_directions, observer_directions : ndarray (n, 3)
        Body-frame unit vectors to the Sun and to the observer (checked by the caller).
    w_ls, w_l : float
        The law's weights (:func:`spinorbit.core.photometry.scattering.law_weights`).

    Returns
    -------
    ndarray (n,)
        L in the square of the vertices' unit.
    """
    g = geometry
    out = np.empty(sun_directions.shape[0])
    _shadowed_sum(g.vertices, g.faces, g.normals, g.areas, g.candidates, g.heights, g.points, g.box_low, g.box_high,
                  g.children, g.leaf, g.order, np.ascontiguousarray(sun_directions, dtype=float),
                  np.ascontiguousarray(observer_directions, dtype=float), float(w_ls), float(w_l), out)
    return out
