"""Independent reference for the mean YORP torque: the facet sum averaged over the rotation and the orbit by brute force.

The quantity is the time average of Rubincam's (2000) zero-conductivity recoil torque on a body spinning
uniformly about a fixed axis (a principal-axis rotator) while the Sun moves on a Kepler ellipse::

    ⟨T⟩ = ⟨ (a/r)² R(φ) Σ_k A_k max(0, n_k · R(φ)ᵀ ŝ(M)) (r_k × n_k) ⟩_{φ, M}

in geometry units (multiply by −P(a), the recoil pressure at the semi-major axis, for a torque), expressed
in the spin frame: z along the spin axis, the orbit normal W in the y–z plane at the obliquity ε from z
(W = (0, sin ε, cos ε)), x = y × z. So ⟨T_z⟩ changes the spin rate, ⟨T_y⟩ the obliquity and ⟨T_x⟩
precesses the spin axis about W.

It is computed literally, as a time average: the rotation phase φ on n_phase equal steps of 2π, the mean
anomaly M on n_anomaly equal steps of 2π (midpoints), the Sun's direction and distance from Kepler's
equation solved by Newton's method at each M, and the facet sum with its clipped cosine at every (φ, M).
Nothing of the package's averaging is used (no closed form, no representation, no exchange of the
averages), so it checks :mod:`spinorbit.core.averaging.recoil_orbit_mean` from outside.

The clipped cosine makes the integrand kinked in φ and M, so the trapezoidal rule converges as the
square of the spacing, not geometrically. :func:`converged_mean_torque` doubles both grids until a
doubling changes every component by at most ``rtol`` of its size; the last change is returned with the
result (the error of the finer grid is about a third of it where the N⁻² law holds, and never more
than the change itself in the runs of tests/test_yorp_mean.py).
"""

import math

import numba
import numpy as np


@numba.njit(cache=False)
def _time_average(normals, areas, arms, spin_to_body, sun, weights, n_phase):
    # spin_to_body: rotation of spin-frame vectors to the body frame at φ = 0 (rows: body axes).
    out = np.zeros(3)
    count = normals.shape[0]
    for k in range(sun.shape[0]):
        acc = np.zeros(3)
        for j in range(n_phase):
            phi = 2.0 * math.pi * j / n_phase
            c, s = math.cos(phi), math.sin(phi)
            # The Sun in the frame co-rotating with the body: R_z(φ)ᵀ applied to the spin-frame direction.
            rx, ry, rz = c * sun[k, 0] + s * sun[k, 1], -s * sun[k, 0] + c * sun[k, 1], sun[k, 2]
            bx = spin_to_body[0, 0] * rx + spin_to_body[0, 1] * ry + spin_to_body[0, 2] * rz
            by = spin_to_body[1, 0] * rx + spin_to_body[1, 1] * ry + spin_to_body[1, 2] * rz
            bz = spin_to_body[2, 0] * rx + spin_to_body[2, 1] * ry + spin_to_body[2, 2] * rz
            tx = ty = tz = 0.0
            for f in range(count):
                lit = normals[f, 0] * bx + normals[f, 1] * by + normals[f, 2] * bz
                if lit > 0.0:
                    w = areas[f] * lit
                    tx += w * arms[f, 0]
                    ty += w * arms[f, 1]
                    tz += w * arms[f, 2]
            # Body torque → co-rotating spin frame → inertial spin frame (R_z(φ)).
            ux = spin_to_body[0, 0] * tx + spin_to_body[1, 0] * ty + spin_to_body[2, 0] * tz
            uy = spin_to_body[0, 1] * tx + spin_to_body[1, 1] * ty + spin_to_body[2, 1] * tz
            uz = spin_to_body[0, 2] * tx + spin_to_body[1, 2] * ty + spin_to_body[2, 2] * tz
            acc[0] += c * ux - s * uy
            acc[1] += s * ux + c * uy
            acc[2] += uz
        for i in range(3):
            out[i] += weights[k] * acc[i] / n_phase
    return out / sun.shape[0]


def _spin_frame_basis(spin_axis):
    """Rows: the spin frame's x, y, z in the body frame (z along the spin axis)."""
    z = np.asarray(spin_axis, dtype=float)
    z = z / np.linalg.norm(z)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.array([x, np.cross(z, x), z])


def sun_on_kepler_orbit(obliquity, eccentricity, perihelion, n_anomaly):
    """Sun directions (spin frame) and (a/r)² at n_anomaly midpoint mean anomalies of one orbit.

    The orbit's normal is W = (0, sin ε, cos ε); the perihelion lies at the angle ``perihelion`` from the
    node x in the orbit plane. Kepler's equation E − e sin E = M by Newton's method to rounding.
    """
    mean = 2.0 * math.pi * (np.arange(n_anomaly) + 0.5) / n_anomaly
    ecc = mean + eccentricity * np.sin(mean)
    for _ in range(50):
        step = (ecc - eccentricity * np.sin(ecc) - mean) / (1.0 - eccentricity * np.cos(ecc))
        ecc -= step
        if np.max(np.abs(step)) < 1e-15:
            break
    radius = 1.0 - eccentricity * np.cos(ecc)  # r / a
    true = 2.0 * np.arctan2(math.sqrt(1.0 + eccentricity) * np.sin(ecc / 2),
                            math.sqrt(1.0 - eccentricity) * np.cos(ecc / 2))
    node = np.array([1.0, 0.0, 0.0])
    in_plane = np.array([0.0, math.cos(obliquity), -math.sin(obliquity)])  # W × node
    angle = true + perihelion
    directions = np.outer(np.cos(angle), node) + np.outer(np.sin(angle), in_plane)
    return directions, 1.0 / radius**2


def mean_torque(normals, areas, centroids, spin_axis, obliquity, eccentricity=0.0, perihelion=0.7,
                n_phase=256, n_anomaly=256):
    """⟨T⟩ on one grid (module docstring); facets in the body frame, ``spin_axis`` a body-frame vector."""
    basis = _spin_frame_basis(spin_axis)
    sun, weights = sun_on_kepler_orbit(obliquity, eccentricity, perihelion, n_anomaly)
    arms = np.cross(np.asarray(centroids, float), np.asarray(normals, float))
    return _time_average(np.ascontiguousarray(normals, dtype=float), np.ascontiguousarray(areas, dtype=float),
                         np.ascontiguousarray(arms), np.ascontiguousarray(basis.T), np.ascontiguousarray(sun), weights,
                         int(n_phase))


def converged_mean_torque(normals, areas, centroids, spin_axis, obliquity, eccentricity=0.0, perihelion=0.7,
                          rtol=1e-3, start=64, largest=1024):
    """⟨T⟩ with both grids doubled from ``start`` until a doubling changes each component by ≤ rtol of itself.

    Returns
    -------
    torque : ndarray (3,)
        The finest grid's result.
    change : ndarray (3,)
        |last doubling's change| / |torque|, component by component.
    points : int
        The finest grid's points per period (rotation and orbit alike).

    Raises
    ------
    RuntimeError
        Not converged at ``largest`` points (the result would not be a reference).
    """
    n = start
    previous = mean_torque(normals, areas, centroids, spin_axis, obliquity, eccentricity, perihelion, n, n)
    while True:
        n *= 2
        current = mean_torque(normals, areas, centroids, spin_axis, obliquity, eccentricity, perihelion, n, n)
        change = np.abs(current - previous) / np.abs(current)
        if np.all(change <= rtol):
            return current, change, n
        if n >= largest:
            raise RuntimeError(f"mean torque not converged to {rtol:g} at {n} points: changes {change}")
        previous = current


def write_bilobed_obj(path, subdivisions=3):
    """Write a contact-binary-like body as a Wavefront OBJ file (km), by hand, not through spinorbit's writer.

    Two ellipsoids (semi-axes 0.6 × 0.45 × 0.4 and 0.45 × 0.35 × 0.3 km) whose centres sit 0.35 and 0.3 km
    either side of the origin on x, the second turned by 0.5 rad about x and 0.3 rad about z: the union is
    star-shaped about the origin (inside both), non-convex at the neck and without a mirror plane. Each
    vertex of an icosphere direction grid is pushed out to the farther of the two ellipsoids' surfaces.
    """
    from spinorbit.shape.mesh import icosphere

    directions, faces = icosphere(subdivisions)
    turn_x, turn_z = 0.5, 0.3
    rx = np.array([[1, 0, 0], [0, math.cos(turn_x), -math.sin(turn_x)], [0, math.sin(turn_x), math.cos(turn_x)]])
    rz = np.array([[math.cos(turn_z), -math.sin(turn_z), 0], [math.sin(turn_z), math.cos(turn_z), 0], [0, 0, 1]])
    lobes = [(np.array([0.35, 0.0, 0.0]), np.eye(3), np.array([0.6, 0.45, 0.4])),
             (np.array([-0.3, 0.0, 0.0]), rz @ rx, np.array([0.45, 0.35, 0.3]))]
    radii = np.zeros(len(directions))
    for centre, rotation, axes in lobes:
        d = directions @ rotation / axes  # ray and centre in the lobe's unit-sphere coordinates
        c = centre @ rotation / axes
        a, b, cc = np.sum(d * d, axis=1), -2.0 * d @ c, c @ c - 1.0
        radii = np.maximum(radii, (-b + np.sqrt(b * b - 4 * a * cc)) / (2 * a))
    vertices = directions * radii[:, None]
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("# bilobed test body (tests/_yorp_reference.py), km\n")
        stream.writelines(f"v {x:.12f} {y:.12f} {z:.12f}\n" for x, y, z in vertices)
        stream.writelines(f"f {i + 1} {j + 1} {k + 1}\n" for i, j, k in faces)
