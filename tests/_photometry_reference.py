"""References for the photometry tests: the disk-integrated brightness of an ellipsoid as a 2-D mpmath
quadrature of its surface integral, independent of the closed forms it checks; and brute-force ray
casting of a facet model's shadows, independent of the ray tracer's hierarchy and culling.

The ellipsoid is the unit sphere mapped by D = diag(a, b, c) (x = D y, normal ∝ D⁻¹y, dA = abc |D⁻¹y| dΩ).
The integral runs over the y sphere in coordinates whose equator holds w = D⁻¹ô and v = D⁻¹ŝ, so the
region where the surface is lit and seen is the rectangle β ∈ [−π/2, π/2], λ ∈ [α′ − π/2, π/2]; the
integrand is the law evaluated from the surface's own μ, μ₀ and area element.
"""

import mpmath as mp

import numpy as np
from astropy import units as u

from spinorbit.core.model.polyhedron import face_geometry
from spinorbit.core.model.shadowing import subdivision_points
from spinorbit.shape import voxel_shape

#: Digits of the quadratures: far beyond the 1e-13 the closed forms are held to.
DIGITS = 25


def _basis(w, v):
    """Orthonormal e1 ∥ w, e2 in the plane of w and v, e3 = their pole; and the angle α′ from w to v."""
    e1 = w / mp.norm(w)
    cross = mp.matrix([w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2], w[0] * v[1] - w[1] * v[0]])
    if mp.norm(cross) == 0:  # w ∥ v: any pole perpendicular to w
        helper = mp.matrix([1, 0, 0]) if abs(e1[0]) < 0.9 else mp.matrix([0, 1, 0])
        cross = mp.matrix([e1[1] * helper[2] - e1[2] * helper[1], e1[2] * helper[0] - e1[0] * helper[2],
                           e1[0] * helper[1] - e1[1] * helper[0]])
    e3 = cross / mp.norm(cross)
    e2 = mp.matrix([e3[1] * e1[2] - e3[2] * e1[1], e3[2] * e1[0] - e3[0] * e1[2], e3[0] * e1[1] - e3[1] * e1[0]])
    alpha = mp.atan2(mp.fdot(v, e2), mp.fdot(v, e1))
    return e1, e2, e3, alpha


def ellipsoid_brightness(semi_axes, sun, observer, law):
    """∫ S(μ₀, μ) dA over the lit, visible part of the ellipsoid; law "lommel-seeliger" or "lambert"."""
    with mp.workdps(DIGITS):
        a, b, c = (mp.mpf(x) for x in semi_axes)
        inverse = mp.matrix([1 / a, 1 / b, 1 / c])
        w = mp.matrix([mp.mpf(observer[i]) * inverse[i] for i in range(3)])
        v = mp.matrix([mp.mpf(sun[i]) * inverse[i] for i in range(3)])
        e1, e2, e3, alpha = _basis(w, v)

        def integrand(beta, lam):
            y = [mp.cos(beta) * (mp.cos(lam) * e1[i] + mp.sin(lam) * e2[i]) + mp.sin(beta) * e3[i] for i in range(3)]
            scaled = mp.sqrt(sum((y[i] * inverse[i]) ** 2 for i in range(3)))   # |D⁻¹y|
            mu = sum(y[i] * w[i] for i in range(3)) / scaled
            mu0 = sum(y[i] * v[i] for i in range(3)) / scaled
            if mu <= 0 or mu0 <= 0:
                return mp.mpf(0)
            law_value = mu * mu0 / (mu + mu0) if law == "lommel-seeliger" else mu * mu0
            return law_value * a * b * c * scaled * mp.cos(beta)

        return mp.quad(integrand, [-mp.pi / 2, mp.pi / 2], [alpha - mp.pi / 2, mp.pi / 2])


def brute_force_brightness(shape, sun, observer, samples, law_weights=(1.0, 0.0)):
    """Every facet facing both, every sample point, both rays against every other triangle (Möller–Trumbore)."""
    vertices, faces = shape.vertices_km, shape.faces
    normals, areas, _ = face_geometry(vertices, faces)
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    e1, e2 = b - a, c - a
    uv = subdivision_points(samples)
    out = []
    for s, o in zip(sun, observer):
        total = 0.0
        for k in np.nonzero((normals @ s > 0) & (normals @ o > 0))[0]:
            mu0, mu = normals[k] @ s, normals[k] @ o
            points = a[k] + uv[:, :1] * e1[k] + uv[:, 1:] * e2[k]
            free = np.ones(len(points), dtype=bool)
            for d in (s, o):
                p = np.cross(d, e2)                                    # (m, 3)
                det = np.einsum("mi,mi->m", e1, p)
                t = points[:, None, :] - a[None]                        # (P, m, 3)
                with np.errstate(divide="ignore", invalid="ignore"):
                    uu = np.einsum("pmi,mi->pm", t, p) / det
                    q = np.cross(t, e1[None])
                    vv = np.einsum("i,pmi->pm", d, q) / det
                    tt = np.einsum("mi,pmi->pm", e2, q) / det
                hit = (det != 0) & (uu >= 0) & (uu <= 1) & (vv >= 0) & (uu + vv <= 1) & (tt > 0)
                hit[:, k] = False
                free &= ~hit.any(axis=1)
            w_ls, w_l = law_weights
            total += areas[k] * mu * mu0 * (w_ls / (mu + mu0) + w_l) * free.mean()
        out.append(total)
    return np.array(out)


def l_shape(n=4):
    """A base 2n × n × n/2 (x, y, z) and a tower n × n × n on its x < n half (voxels of 1 km)."""
    occupied = np.zeros((2 * n, n, n // 2 + n), dtype=bool)
    occupied[:, :, : n // 2] = True
    occupied[:n, :, n // 2:] = True
    return voxel_shape(occupied, 1.0 * u.km)


#: The geometries of tests/data/photometry_ellipsoid_reference.json: (semi-axes, Sun, observer, law),
#: unit vectors in the body frame; "lambert" only at opposition, where it has a closed form.
CASES = (
    ((1.3, 0.9, 0.6), (0.7, -0.2, 0.5), (0.3, 0.5, 0.8), "lommel-seeliger"),
    ((1.3, 0.9, 0.6), (0.3, 0.5, 0.8), (0.3, 0.5, 0.8), "lommel-seeliger"),
    ((1.3, 0.9, 0.6), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), "lommel-seeliger"),
    ((1.3, 0.9, 0.6), (-0.8, 0.1, 0.2), (0.9, 0.3, -0.1), "lommel-seeliger"),
    ((2.0, 1.0, 0.5), (0.1, 0.2, 0.9), (0.6, -0.6, 0.3), "lommel-seeliger"),
    ((1.3, 0.9, 0.6), (0.3, 0.5, 0.8), (0.3, 0.5, 0.8), "lambert"),
    ((2.0, 1.0, 0.5), (1.0, 1.0, 1.0), (1.0, 1.0, 1.0), "lambert"),
    ((2.0, 1.0, 0.5), (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), "lambert"),
)


def unit(vector):
    norm = sum(x * x for x in vector) ** 0.5
    return tuple(x / norm for x in vector)


if __name__ == "__main__":  # python tests/_photometry_reference.py: regenerates the reference file
    import json
    from pathlib import Path

    rows = []
    for axes, sun, observer, law in CASES:
        value = ellipsoid_brightness(axes, unit(sun), unit(observer), law)
        rows.append({"semi_axes": axes, "sun": unit(sun), "observer": unit(observer), "law": law,
                     "brightness": mp.nstr(value, 20)})
        print(rows[-1])
    target = Path(__file__).parent / "data" / "photometry_ellipsoid_reference.json"
    target.write_text(json.dumps({"generator": "tests/_photometry_reference.py", "digits": DIGITS,
                                  "cases": rows}, indent=1) + "\n")
