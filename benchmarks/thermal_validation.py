"""Shapes and sunlight's recoil, validated and timed: the numbers of docs/thermal.md.

Writes the section ``thermal_validation`` of docs/thermal.md (every number there comes from this
script):

1. exact mass properties: a box against its closed forms (to rounding), ellipsoid meshes (icosphere
   and ICQ) converging to the ellipsoid's volume, moments and Stokes coefficients (Balmino 1994);
2. the recoil torque's harmonic representation against the direct facet sum (worst instantaneous
   direction and the spin-averaged torque), and its cost per evaluation against the facet sum;
3. zero mean spin torque of the mirror-symmetric ellipsoid, and the torque under mesh refinement;
4. the mean YORP evolution of a tumbler (torus + orbit average) against the full integration of the
   same shape, for two sizes and two spans (error versus strength and span);
5. self-shadowing: the ray tracer against an L-shaped block's closed-form shadow, zero mean spin torque
   of the mirror-symmetric L-shape, the cost of the precompute, the shadowed fit's error against the
   ray-traced sum degree by degree, mesh refinement, and mean YORP with and without shadows on rough
   Gaussian random spheres;
6. the cost of the full run against the mean one at matched accuracy of the mean quantities, measured
   over spans the full run can afford, and the 10⁶-yr mean run.

Usage::

    PYTHONPATH=$PWD python benchmarks/thermal_validation.py            # ≈ 6–8 min
    PYTHONPATH=$PWD python benchmarks/thermal_validation.py --long     # + the 640-yr span, ≈ 5 min more
    PYTHONPATH=$PWD python benchmarks/thermal_validation.py --no-write # print only
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numba
import numpy as np
from astropy import units as u

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import interleaved_timings, machine_line, write_section  # noqa: E402

from spinorbit.core.averaging.thermal_mean import (  # noqa: E402
    THERMAL_POINTS_ORBIT,
    THERMAL_POINTS_S,
    THERMAL_POINTS_Z,
    mean_thermal_rates,
    orbital_period,
    propagate_mean_thermal,
    recoil_only_model,
)
from spinorbit.core.dynamics.equations import make_model  # noqa: E402
from spinorbit.core.elements.canonical import inertia_constants  # noqa: E402
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C  # noqa: E402
from spinorbit.core.integrators.elements import elements_of_state  # noqa: E402
from spinorbit.core.integrators.quaternion import integrate_quaternion  # noqa: E402
from spinorbit.core.model.perturbers import kepler_source  # noqa: E402
from spinorbit.core.model.polyhedron import face_geometry, mass_properties, stokes_coefficients  # noqa: E402
from spinorbit.core.model.shadowing import shadow_geometry, shadowed_recoil_sums  # noqa: E402
from spinorbit.core.model.thermal import facet_force_torque, pack_thermal, thermal_force_torque_xyz  # noqa: E402
from spinorbit.shape import (  # noqa: E402
    box_shape,
    ellipsoid_shape,
    gaussian_random_sphere,
    icq_grid,
    icq_mesh,
    principal_facets,
    principal_vertices,
    rigid_body_from_shape,
    shape_mass_properties,
    thermal_block,
    voxel_shape,
)

GM_SUN = 0.01720209895**2  # au³/day²
DENSITY = 2000 * u.kg / u.m**3
SEMI_AXES = (1.0, 0.8, 0.6)
YEAR = 365.25
ORBIT_FRAME = np.diag([-1.0, -1.0, 1.0])  # inertial → (P, Q, W) of the Sun's row of :func:`tumbler`
#: Spans of the full-against-mean cost table (years; each costs ≈ 0.4 CPU s per year in full) and the
#: mean run's step (the 10⁶-yr run's).
SPANS_YR, LONG_SPAN_YR, MEAN_STEP_YR = (10, 40, 160), 640, 5000.0
#: Timed repeats of the 10⁶-yr mean run (≈ 3 CPU s each).
MEAN_REPEATS = 3


def mass_section():
    h = (1.5, 1.0, 0.7)
    cube = box_shape(h * u.km)
    vertices, faces = cube.vertices_km, cube.faces
    volume, _, inertia = mass_properties(vertices + np.array([0.3, -0.2, 5.0]), faces)
    exact = volume / 3 * np.array([h[1] ** 2 + h[2] ** 2, h[0] ** 2 + h[2] ** 2, h[0] ** 2 + h[1] ** 2])
    c, _ = stokes_coefficients(vertices, faces, 1.0)
    c20 = (h[2] ** 2 - 0.5 * (h[0] ** 2 + h[1] ** 2)) / 3
    lines = ["**Box** 3 × 2 × 1.4, offset (0.3, −0.2, 5) from the origin, against its closed forms: "
             f"volume {abs(volume / (8 * h[0] * h[1] * h[2]) - 1):.1e}, moments "
             f"{np.abs(np.diag(inertia) / exact - 1).max():.1e}, C20 {abs(c[2, 0] / c20 - 1):.1e} (relative).", "",
             "**Ellipsoid** (1, 0.8, 0.6) as a subdivided icosahedron: relative errors against the ellipsoid's volume "
             "4πabc/3, moments m(b² + c²)/5 …, and Stokes coefficients (Balmino 1994); each level cuts them by 4 "
             "(the edge length squared).", "",
             "| level | faces | volume | moments | C20 | C40 | C44 |", "|---|---|---|---|---|---|---|"]
    a, b, cc = SEMI_AXES
    s20, s22 = (2 * cc * cc - a * a - b * b) / 10, (a * a - b * b) / 20
    for level in (2, 3, 4, 5, 6):
        shape = ellipsoid_shape(SEMI_AXES * u.km, subdivisions=level)
        volume, _, inertia = mass_properties(shape.vertices_km, shape.faces)
        stokes, _ = stokes_coefficients(shape.vertices_km, shape.faces, 1.0)
        moments = volume / 5 * np.array([b * b + cc * cc, a * a + cc * cc, a * a + b * b])
        lines.append(f"| {level} | {len(shape)} | {abs(volume / (4 / 3 * math.pi * a * b * cc) - 1):.2e} | "
                     f"{np.abs(np.diag(inertia) / moments - 1).max():.2e} | {abs(stokes[2, 0] / s20 - 1):.2e} | "
                     f"{abs(stokes[4, 0] / (15 / 7 * (s20**2 + 2 * s22**2)) - 1):.2e} | "
                     f"{abs(stokes[4, 4] / (5 / 28 * s22**2) - 1):.2e} |")
    radius = lambda d: 1 / np.sqrt((d[:, 0] / a) ** 2 + (d[:, 1] / b) ** 2 + (d[:, 2] / cc) ** 2) * u.km  # noqa: E731
    icq = []
    for q in (8, 16, 32):
        vertices, faces = icq_mesh(icq_grid(radius, q))
        vertices = vertices.to_value(u.km)
        icq.append(f"q = {q}: {abs(mass_properties(vertices, faces)[0] / (4 / 3 * math.pi * a * b * cc) - 1):.2e}")
    lines += ["", "The same ellipsoid as an ICQ grid, volume error: " + ", ".join(icq) + "."]
    return lines


@numba.njit(cache=False)
def _direct_sum(sx, sy, sz, normals, areas, arms):
    """The facet sum compiled, for a fair time comparison with the representation."""
    tx = ty = tz = 0.0
    for k in range(areas.shape[0]):
        lit = normals[k, 0] * sx + normals[k, 1] * sy + normals[k, 2] * sz
        if lit > 0.0:
            w = lit * areas[k]
            tx += w * arms[k, 0]
            ty += w * arms[k, 1]
            tz += w * arms[k, 2]
    return tx, ty, tz


@numba.njit(cache=False)
def _loop_representation(n, block):
    acc = 0.0
    for i in range(n):
        acc += thermal_force_torque_xyz(0.3 + 1e-9 * i, 0.4, 0.5, 1.0, block, 0)[5]
    return acc


@numba.njit(cache=False)
def _loop_direct(n, normals, areas, arms):
    acc = 0.0
    for i in range(n):
        acc += _direct_sum(0.3 + 1e-9 * i, 0.4, 0.5, normals, areas, arms)[2]
    return acc


def spin_directions(latitude, count=256):
    phase = 2 * math.pi * np.arange(count) / count
    return np.stack([math.cos(latitude) * np.cos(phase), math.cos(latitude) * np.sin(phase),
                     math.sin(latitude) * np.ones(count)], axis=1)


def facets(shape):
    return principal_facets(shape, shape_mass_properties(shape, density=DENSITY))


def torque_section():
    shape = gaussian_random_sphere(1.0 * u.km, 0.1, seed=3, subdivisions=4)
    normals, areas, centroids = facets(shape)
    rng = np.random.default_rng(1)
    directions = rng.standard_normal((200, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    direct = np.array([facet_force_torque(normals, areas, centroids, s)[1] for s in directions])
    scale = np.abs(direct).max()
    spin = {lat: np.array([facet_force_torque(normals, areas, centroids, s)[1] for s in spin_directions(lat)])
            for lat in (0.2, 0.7, 1.2)}
    arms = np.ascontiguousarray(np.cross(centroids, normals))
    n_calls = 200_000
    _loop_direct(10, normals, areas, arms)
    direct_time = interleaved_timings([lambda: _loop_direct(2000, normals, areas, arms)], 5)[0][0].median / 2000
    lines = [f"A Gaussian random sphere (σ = 0.1, seed 3, {len(shape)} facets). Errors of the degree-L representation "
             "against the direct facet sum, relative to the largest instantaneous torque: the worst of 200 random "
             "Sun directions, and the spin-averaged torque about z (256 phases) at latitudes 0.2, 0.7, 1.2 rad. "
             f"Time per evaluation (force and torque), against {direct_time * 1e9:.0f} ns for the compiled facet sum "
             "(torque only).", "",
             "| L | worst direction | spin-averaged (worst latitude) | ns per call |", "|---|---|---|---|"]
    for degree in (4, 8, 12, 16, 24):
        block = pack_thermal(normals, areas, centroids, degree, 1.0, 1.0)
        fast = -np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[3:] for s in directions])
        averaged = max(abs(-np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[5] for s in spin_directions(lat)]).mean()
                           - spin[lat][:, 2].mean()) for lat in spin) / scale
        _loop_representation(10, block)
        timing = interleaved_timings([lambda: _loop_representation(n_calls, block)], 5)[0][0].median / n_calls
        lines.append(f"| {degree} | {np.abs(fast - direct).max() / scale:.1e} | {averaged:.1e} | {timing * 1e9:.0f} |")
    symmetric = facets(ellipsoid_shape(SEMI_AXES * u.km, subdivisions=4))
    worst, amplitude = 0.0, 0.0
    for lat in (0.1, 0.5, 0.9, 1.3):
        torque = np.array([facet_force_torque(*symmetric, s)[1] for s in spin_directions(lat)])
        worst, amplitude = max(worst, abs(torque[:, 2].mean())), max(amplitude, np.abs(torque).max())
    refined = []
    probe = directions[:30]
    for level in (3, 4, 5, 6):
        n_, a_, c_ = facets(gaussian_random_sphere(1.0 * u.km, 0.1, seed=9, subdivisions=level))
        refined.append(np.array([facet_force_torque(n_, a_, c_, s)[1] for s in probe]))
    steps = [np.abs(refined[k + 1] - refined[k]).max() / np.abs(refined[-1]).max() for k in range(3)]
    lines += ["", f"Mirror-symmetric ellipsoid mesh (5120 facets): mean spin torque / instantaneous amplitude "
              f"{worst / amplitude:.1e} (zero to rounding). Mesh refinement of one random surface (seed 9), largest "
              "change of the torque between icosphere levels 3→4, 4→5, 5→6: "
              + ", ".join(f"{x:.1e}" for x in steps) + " of its size."]
    return lines


def tumbler(radius_km, recoil_only=True):
    shape = gaussian_random_sphere(radius_km * u.km, 0.15, seed=5, subdivisions=3)
    properties = shape_mass_properties(shape, density=DENSITY)
    moments = np.array(rigid_body_from_shape(shape, density=DENSITY).principal_moments)
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)
    model = make_model(moments, [sun], thermal=thermal_block(shape, properties, degree=8), thermal_sun=0)
    if recoil_only:
        model = recoil_only_model(model)
    omega = 2 * math.pi / 0.25
    q = np.array([0.9, 0.2, -0.3, 0.25])
    return model, np.array([*(q / np.linalg.norm(q)), 0.3 * omega, 0.1 * omega, omega])


def mean_section():
    lines = ["A tumbling Gaussian random sphere (σ = 0.15, seed 5, density 2000 kg/m³, 6 h), on a = 1 au, e = 0.1, "
             "under the recoil alone (L = 8). Full: DOP853 (rtol 1e-11) on the same model; mean: "
             "`propagate_mean_thermal` (16 × 8 × 16 grid, one-orbit steps). Relative error of the change of S, Z, H "
             "since t = 0, at whole orbits.", "",
             "| radius | span | ΔZ/Z (full) | error ΔS | error ΔZ | error ΔH | full (CPU s) | mean (CPU s) |",
             "|---|---|---|---|---|---|---|---|"]
    for radius in (0.06, 0.2):
        model, y0 = tumbler(radius)
        el0 = elements_of_state(y0, model, ORBIT_FRAME)
        period = orbital_period(model)
        for years in (10, 40):
            t_out = period * np.arange(1, years + 1)
            start = time.process_time()
            mean, _ = propagate_mean_thermal(el0, 0.0, t_out, model, ORBIT_FRAME, step=period, with_gravity=False)
            mean_s = time.process_time() - start
            start = time.process_time()
            states = integrate_quaternion(y0, 0.0, t_out, model, rtol=1e-11)
            full_s = time.process_time() - start
            full = np.array([elements_of_state(y, model, ORBIT_FRAME) for y in states])
            errors = [abs((mean[-1, k] - el0[k]) / (full[-1, k] - el0[k]) - 1) for k in range(3)]
            lines.append(f"| {radius * 1000:.0f} m | {years} yr | {(full[-1, 1] - el0[1]) / el0[1]:.2e} | "
                         + " | ".join(f"{e:.1e}" for e in errors) + f" | {full_s:.1f} | {mean_s:.2f} |")
    return lines


def _l_shape(cells=4):
    """A tower (cells³) on the x < cells half of a 2·cells × cells × cells/2 base: the closed-form shadow body."""
    occupied = np.zeros((2 * cells, cells, cells // 2 + cells), dtype=bool)
    occupied[:, :, :cells // 2] = True
    occupied[:cells, :, cells // 2:] = True
    return voxel_shape(occupied, 1.0 * u.km), cells


def _principal_geometry(shape, samples):
    properties = shape_mass_properties(shape, density=DENSITY)
    vertices = principal_vertices(shape, properties) / 1000.0  # km: arms in units of the 1-km radius
    normals, areas, centroids = face_geometry(vertices, shape.faces)
    return shadow_geometry(vertices, shape.faces, samples), (normals, areas, centroids)


def _unshadowed(facet_data, directions):
    return np.array([np.concatenate(facet_force_torque(*facet_data, s)) for s in directions])


def _orbit_directions(obliquity, n_spin=64, n_orbit=32):
    """Sun directions on the body (spin axis z) over n_spin phases × n_orbit longitudes of a circular orbit
    whose normal is tilted by ``obliquity``, and the rotations back to the spin frame."""
    theta = 2 * math.pi * np.arange(n_orbit) / n_orbit
    phi = 2 * math.pi * np.arange(n_spin) / n_spin
    sun = np.stack([np.cos(theta), np.sin(theta) * math.cos(obliquity), -np.sin(theta) * math.sin(obliquity)], axis=1)
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    body = np.stack([c * sun[None, :, 0] + s * sun[None, :, 1], -s * sun[None, :, 0] + c * sun[None, :, 1],
                     np.broadcast_to(sun[None, :, 2], (n_spin, n_orbit))], axis=-1)
    return body.reshape(-1, 3), np.repeat(phi, n_orbit)


def _mean_yorp(torques, phases):
    """⟨T_z⟩ (spin rate) and −⟨T_y⟩ (obliquity, the orbit normal in the y–z plane) in the spin frame."""
    c, s = np.cos(phases), np.sin(phases)
    ty = s * torques[:, 0] + c * torques[:, 1]  # R_z(φ) T_body
    return torques[:, 2].mean(), -ty.mean()


def shadow_section(quick=False):
    lines = []
    # 1. The closed-form body.
    shape, cells = _l_shape()
    normals, areas, centroids = face_geometry(shape.vertices_km, shape.faces)
    rows = []
    for samples in (1, 2, 4, 8):
        geometry = shadow_geometry(shape.vertices_km, shape.faces, samples)
        errors = []
        for elevation in (50.0, 70.0):
            e = math.radians(elevation)
            s = np.array([-math.cos(e), 0.0, math.sin(e)])
            length = min(cells, cells / math.tan(e))
            expected = facet_force_torque(normals, areas, centroids, s)[0][2] - length * cells * math.sin(e)
            force = shadowed_recoil_sums(geometry, s)[0][0, 2]
            errors.append(abs(force - expected) / (length * cells * math.sin(e)))
        rows.append(f"| {samples} | {errors[0]:.1e} | {errors[1]:.1e} | {2.0 / samples / (cells / math.tan(math.radians(70.0))):.1e} |")
    lines += [f"**Closed form.** An L-shaped block of {len(shape)} facets (voxels of 1: a base 8 × 4 × 2, a tower 4 × 4 × 4 "
              "on its x < 4 half): for the Sun at elevation e beyond the tower, in its symmetry plane, the tower "
              "shades a rectangle of length min(4, 4 cot e) of the floor, so the shadowed force is the unshadowed facet "
              "sum (exact for flat faces) less the rectangle's. Error of the floor's shadowed force relative to the "
              "shadow's own part, against q (q² sample points per facet); the bound is the strip of sub-triangles the "
              "shadow's edge crosses, 2/(q ℓ) of the shadow of length ℓ (70°).", "",
              "| q | e = 50° | e = 70° | bound (70°) |", "|---|---|---|---|"] + rows
    vertices = shape.vertices_km - mass_properties(shape.vertices_km, shape.faces)[1]
    vertices[:, 1] = shape.vertices_km[:, 1] - cells / 2  # the mirror plane y = 2 through the centre, exactly
    geometry = shadow_geometry(vertices, shape.faces, 2)
    facet_data = face_geometry(vertices, shape.faces)
    block = pack_thermal(*facet_data, 8, 1.0, 1.0, shadowing=geometry)
    worst = fitted = amplitude = 0.0
    for latitude in (0.2, 0.7, 1.2):
        directions = spin_directions(latitude)
        torque = shadowed_recoil_sums(geometry, directions)[1]
        fast = np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[5] for s in directions])
        worst, fitted = max(worst, abs(torque[:, 2].mean())), max(fitted, abs(fast.mean()))
        amplitude = max(amplitude, np.abs(torque).max())
    lines += ["", f"**Mirror symmetry.** The same L-shape spun about z through its centre of mass (the mirror plane "
              f"y = 2 contains the axis), shadowed (q = 2): mean spin torque / instantaneous amplitude {worst / amplitude:.1e} "
              f"from the ray-traced sum and {fitted / amplitude:.1e} from its L = 8 fit, at latitudes 0.2, 0.7, 1.2 rad "
              "(zero to rounding: the shadows keep the symmetry)."]

    # 2. Cost of the precompute and the representation's convergence on a rough Gaussian random sphere.
    rough = gaussian_random_sphere(1.0 * u.km, 0.3, seed=3, subdivisions=4)
    start = time.process_time()
    geometry, facet_data = _principal_geometry(rough, 1)
    prepare_s = time.process_time() - start
    fit_s = {}
    for samples in (1, 2):
        g = geometry if samples == 1 else _principal_geometry(rough, 2)[0]
        start = time.process_time()
        pack_thermal(*facet_data, 8, 1.0, 1.0, shadowing=g)
        fit_s[samples] = time.process_time() - start
    rng = np.random.default_rng(1)
    probe = rng.standard_normal((200, 3))
    probe /= np.linalg.norm(probe, axis=1, keepdims=True)
    direct = shadowed_recoil_sums(geometry, probe)[1]
    scale = np.abs(direct).max()
    plain = _unshadowed(facet_data, probe)[:, 3:]
    spin = {lat: shadowed_recoil_sums(geometry, spin_directions(lat))[1][:, 2].mean() for lat in (0.2, 0.7, 1.2)}
    spin_plain = {lat: _unshadowed(facet_data, spin_directions(lat))[:, 5].mean() for lat in spin}
    lines += ["", f"**A rough body.** Gaussian random sphere σ = 0.3 (seed 3, {len(rough)} facets; "
              f"{geometry.candidates.mean():.0%} of the facets have a vertex above their plane and get rays). Preparing "
              f"the rays (culling, hierarchy) took {prepare_s:.2f} CPU s; the L = 8 fit over its {2 * 18 * 18} Sun "
              f"directions {fit_s[1]:.1f} CPU s with the centroid (q = 1) and {fit_s[2]:.1f} s with q = 2 (load "
              f"{os.getloadavg()[0]:.1f}). Shadowing changes the instantaneous torque by up to "
              f"{np.abs(direct - plain).max() / scale:.0%} of its largest value. Errors of the degree-L fit against the "
              "ray-traced sum (q = 1), relative to the largest instantaneous torque (as above), next to the unshadowed "
              "representation's against the unshadowed sum of the same shape:", "",
              "| L | worst direction | spin-averaged (worst latitude) | unshadowed: worst | unshadowed: spin-averaged "
              "| ns per call: shadowed (all degrees) | unshadowed |", "|---|---|---|---|---|---|---|"]
    blocks = {}
    for degree in ((4, 8, 16) if quick else (4, 8, 12, 16, 24)):
        block = blocks[degree] = pack_thermal(*facet_data, degree, 1.0, 1.0, shadowing=geometry)
        plain_block = pack_thermal(*facet_data, degree, 1.0, 1.0)
        fast = -np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[3:] for s in probe])
        fast_plain = -np.array([thermal_force_torque_xyz(*s, 1.0, plain_block, 0)[3:] for s in probe])
        averaged = max(abs(-np.mean([thermal_force_torque_xyz(*s, 1.0, block, 0)[5] for s in spin_directions(lat)])
                           - spin[lat]) for lat in spin) / scale
        averaged_plain = max(abs(-np.mean([thermal_force_torque_xyz(*s, 1.0, plain_block, 0)[5]
                                           for s in spin_directions(lat)]) - spin_plain[lat]) for lat in spin) / scale
        _loop_representation(10, block)
        timings = interleaved_timings([lambda b=block: _loop_representation(100_000, b),
                                       lambda b=plain_block: _loop_representation(100_000, b)], 5)
        shadowed_ns, plain_ns = (t.median / 100_000 * 1e9 for t in timings[0])
        lines.append(f"| {degree} | {np.abs(fast - direct).max() / scale:.1e} | {averaged:.1e} | "
                     f"{np.abs(fast_plain - plain).max() / scale:.1e} | {averaged_plain:.1e} | {shadowed_ns:.0f} | "
                     f"{plain_ns:.0f} |")
    doubled = pack_thermal(*facet_data, 8, 1.0, 1.0, shadowing=geometry, shadow_grid=36)
    aliasing = np.abs(np.array([np.subtract(thermal_force_torque_xyz(*s, 1.0, doubled, 0)[3:],
                                            thermal_force_torque_xyz(*s, 1.0, blocks[8], 0)[3:]) for s in probe])).max()
    aliasing_spin = max(abs(np.mean([thermal_force_torque_xyz(*s, 1.0, doubled, 0)[5]
                                     - thermal_force_torque_xyz(*s, 1.0, blocks[8], 0)[5] for s in spin_directions(lat)]))
                        for lat in spin)
    lines += ["", "The shadowed torque is kinked where a facet's lit share starts to fall, so the fit converges as a "
              "power of L, like the unshadowed one, not geometrically. Its odd degrees do not vanish, which makes an "
              "evaluation cost more than an unshadowed one of the same degree (the last two columns, timed "
              "interleaved). The fit's quadrature has 2(L + 1) Gauss–Legendre latitudes: doubling them to 36 changes "
              f"the L = 8 torque by {aliasing / scale:.1e} (worst direction) and {aliasing_spin / scale:.1e} "
              "(spin-averaged), the aliasing of the kinked field's higher degrees into the fit."]

    # 3. Mesh refinement.
    probe30 = probe[:30]
    refined, means = [], []
    levels = (3, 4, 5) if quick else (3, 4, 5, 6)
    for level in levels:
        g, _ = _principal_geometry(gaussian_random_sphere(1.0 * u.km, 0.3, seed=9, subdivisions=level), 1)
        refined.append(shadowed_recoil_sums(g, probe30)[1])
        means.append(shadowed_recoil_sums(g, spin_directions(0.7, 128))[1][:, 2].mean())
    size = np.abs(refined[-1]).max()
    steps = [np.abs(refined[k + 1] - refined[k]).max() / size for k in range(len(levels) - 1)]
    mean_steps = [abs(means[k + 1] - means[k]) / size for k in range(len(levels) - 1)]
    arrows = ", ".join(f"{a}→{b}" for a, b in zip(levels[:-1], levels[1:]))
    lines += ["", f"**Mesh refinement** of one rough surface (σ = 0.3, seed 9), shadowed (q = 1), icosphere levels {arrows}: "
              "largest change of the instantaneous torque (30 directions) " + ", ".join(f"{x:.1e}" for x in steps)
              + "; of the spin-averaged T_z at latitude 0.7 " + ", ".join(f"{x:.1e}" for x in mean_steps)
              + " (of the torque's size). The surface itself changes with the level (its facets resolve the same "
              "random field better), so these are the steps of the shape and its shadows together."]

    # 4. Mean YORP with and without shadows.
    lines += ["", "**Mean YORP with and without shadows** on Gaussian random spheres (5120 facets, q = 1, spin about "
              "the axis of largest moment, circular orbit at obliquity ε): ⟨T_z⟩, which changes the spin rate, and "
              "the obliquity torque −⟨T_y⟩ (orbit normal in the y–z plane), averaged over 128 spin phases × 64 orbital "
              "longitudes of the ray-traced sums; in units of P R³ (R = 1 km), and the change shadowing makes. The "
              "last column is the largest change of the shadowed values between this grid and every other point of it "
              "(64 × 32), relative to each: the kinked integrand makes the trapezoidal average converge as the "
              "square of the spacing, not geometrically.", "",
              "| σ | seed | ⟨T_z⟩ ε = 0°: plain → shadowed | ε = 45° | ε = 90° | obliquity torque ε = 45° | grid |",
              "|---|---|---|---|---|---|---|"]
    cases = [(0.3, 1)] if quick else [(0.2, 1), (0.3, 1), (0.3, 2)]
    for sigma, seed in cases:
        g, facet_data = _principal_geometry(gaussian_random_sphere(1.0 * u.km, sigma, seed=seed, subdivisions=4), 1)
        cells, grid_change = [], 0.0
        for obliquity in (0.0, 45.0, 90.0):
            directions, phases = _orbit_directions(math.radians(obliquity), 128, 64)
            torque = shadowed_recoil_sums(g, directions)[1]
            with_shadow = _mean_yorp(torque, phases)
            half = _mean_yorp(torque.reshape(128, 64, 3)[::2, ::2].reshape(-1, 3), phases.reshape(128, 64)[::2, ::2].ravel())
            grid_change = max(grid_change, abs(half[0] / with_shadow[0] - 1),
                              abs(half[1] / with_shadow[1] - 1) if obliquity == 45.0 else 0.0)
            cells.append((_mean_yorp(_unshadowed(facet_data, directions)[:, 3:], phases), with_shadow))
        spin_cells = [f"{w[0]:.2e} → {s[0]:.2e} ({s[0] / w[0] - 1:+.0%})" for w, s in cells]
        w, s = cells[1]
        lines.append(f"| {sigma} | {seed} | " + " | ".join(spin_cells)
                     + f" | {w[1]:.2e} → {s[1]:.2e} ({s[1] / w[1] - 1:+.0%}) | {grid_change:.1e} |")
    lines += ["", "The brief cites Rozitis & Green (2012) for changes of tens of per cent on irregular bodies; their "
              "thermophysical model also has self-heating and roughness, which this zero-conductivity model has not, "
              "so only the sizes compare."]
    return lines


#: Tolerances of the full runs: the reference, and the looser ones whose mean-quantity errors are measured.
REFERENCE_RTOL, LOOSER_RTOLS = 1e-11, (1e-10, 3e-10, 1e-9)


def _component_errors(elements, reference, el0):
    """Relative errors of the changes of S, Z, H since t = 0."""
    return [abs((elements[k] - reference[k]) / (reference[k] - el0[k])) for k in range(3)]


def _changes_error(elements, reference, el0):
    """Largest relative error of the changes of S, Z, H since t = 0."""
    return max(_component_errors(elements, reference, el0))


def _grid_convergence(model, el0, period):
    """Largest relative change of the mean rates d(S, Z, H)/dt from the default grid to a finer one, per grid."""
    ic = inertia_constants(*(model[k] for k in (BODY_A, BODY_B, BODY_C)))
    recoil = recoil_only_model(model)
    rates = {}
    for grid in ((12, 6, 12), (THERMAL_POINTS_S, THERMAL_POINTS_Z, THERMAL_POINTS_ORBIT), (24, 12, 24), (48, 24, 48)):
        out = np.empty(4)
        mean_thermal_rates(0.0, el0, recoil, ORBIT_FRAME, ic, *grid, period, out)
        rates[grid] = out[:3]
    finest = rates[(48, 24, 48)]
    return {grid: float(np.abs(r / finest - 1).max()) for grid, r in rates.items() if grid != (48, 24, 48)}


def cost_section(spans_yr):
    """Full against mean at matched accuracy over measured spans, and the 10⁶-yr mean run."""
    model, y0 = tumbler(0.2)
    el0 = elements_of_state(y0, model, ORBIT_FRAME)
    period = orbital_period(model)
    rows, measured = [], []
    for years in spans_yr:
        t_end = np.array([years * period])
        runs = {}
        for rtol in (REFERENCE_RTOL, *LOOSER_RTOLS):
            start = time.process_time()
            state = integrate_quaternion(y0, 0.0, t_end, model, rtol=rtol)[-1]
            runs[rtol] = (elements_of_state(state, model, ORBIT_FRAME), time.process_time() - start)
        reference = runs[REFERENCE_RTOL][0]
        start = time.process_time()
        mean, _ = propagate_mean_thermal(el0, 0.0, t_end, model, ORBIT_FRAME, step=min(years, MEAN_STEP_YR) * YEAR,
                                         with_gravity=False)
        mean_s = time.process_time() - start
        mean_error = _changes_error(mean[-1], reference, el0)
        worst_component = "SZH"[int(np.argmax(_component_errors(mean[-1], reference, el0)))]
        errors = {rtol: _changes_error(runs[rtol][0], reference, el0) for rtol in LOOSER_RTOLS}
        matched = max([r for r in LOOSER_RTOLS if errors[r] <= mean_error], default=REFERENCE_RTOL)
        matched_s = runs[matched][1]
        measured.append((years, matched, matched_s, mean_s, runs[REFERENCE_RTOL][1], mean_error,
                         {r: (errors[r], runs[r][1]) for r in LOOSER_RTOLS}, worst_component))
        rows.append(f"| {years} yr | {mean_error:.1e} | {mean_s:.2f} | {runs[REFERENCE_RTOL][1]:.1f} | "
                    + " | ".join(f"{errors[r]:.1e} ({runs[r][1]:.1f} s)" for r in LOOSER_RTOLS)
                    + f" | {matched:.0e} | {matched_s / mean_s:.0f}× |")
    lines = ["The 200 m tumbler of the table above (recoil alone). Each span is run four times in full (DOP853, "
             "rtol 1e-11 as the reference and three looser tolerances) and once in the mean (steps of "
             f"min(span, {MEAN_STEP_YR:.0f} yr), one output at the end). The error is the largest relative error of the "
             "changes of S, Z, H against the reference; the matched full run is the loosest whose error does not "
             "exceed the mean run's. CPU seconds of this process.", "",
             "| span | mean: error | mean (s) | full 1e-11 (s) | 1e-10: error (s) | 3e-10: error (s) | 1e-9: error (s) "
             "| matched rtol | matched full / mean |", "|---|---|---|---|---|---|---|---|---|"] + rows
    model_g, y0_g = tumbler(0.2, recoil_only=False)
    el0_g = elements_of_state(y0_g, model_g, ORBIT_FRAME)
    t_out = np.linspace(0.0, 1e6, 101)[1:] * YEAR
    runs = {}
    for step_yr in (MEAN_STEP_YR, MEAN_STEP_YR / 2):
        start = time.process_time()
        elements, steps = propagate_mean_thermal(el0_g, 0.0, t_out, model_g, ORBIT_FRAME, step=step_yr * YEAR)
        runs[step_yr] = (elements, steps, time.process_time() - start)
    coarse, fine = runs[MEAN_STEP_YR], runs[MEAN_STEP_YR / 2]
    # The cost of the 10⁶-yr run: repeats of it (CPU s), median and range.
    repeats = interleaved_timings([lambda: propagate_mean_thermal(el0_g, 0.0, t_out, model_g, ORBIT_FRAME,
                                                                  step=MEAN_STEP_YR * YEAR)], MEAN_REPEATS,
                                  clock=time.process_time)[0][0]
    load = os.getloadavg()[0]
    mean_1e6 = repeats.median
    stepping = np.abs((coarse[0][:, :3] - fine[0][:, :3]) / (fine[0][:, :3] - el0_g[:3])).max()
    # The same, relative to the largest change over the run (ΔH passes near zero on the way, where the
    # per-output ratio above is large for a small absolute difference).
    stepping_of_largest = (np.abs(coarse[0][:, :3] - fine[0][:, :3]).max(axis=0)
                           / np.abs(fine[0][:, :3] - el0_g[:3]).max(axis=0)).max()
    grid_change = _grid_convergence(model, el0, period)
    years, matched, matched_s, mean_s, reference_s, _, looser, _ = measured[-1]
    mean_errors = [m[5] for m in measured]
    # Over 10⁶ yr the mean run's error is its step error as well: match the full run to the larger of the two.
    loose = max([r for r in LOOSER_RTOLS if looser[r][0] <= max(stepping, max(mean_errors))], default=matched)
    per_year = matched_s / years
    full_1e6 = per_year * 1e6
    ratio = full_1e6 / mean_1e6
    verdict = (f"the goal of 10⁴× is met ({ratio / 1e4:.1f} × 10⁴)" if ratio >= 1e4
               else f"short of the goal of 10⁴× by {1e4 / ratio:.2f}×")
    worst = ", ".join(f"Δ{m[7]} at {m[0]} yr" for m in measured)
    lines += ["", f"Measured: the ratio grows in proportion to the span ({', '.join(f'{m[2] / m[3]:.0f}×' for m in measured)} "
              f"at {', '.join(f'{m[0]} yr' for m in measured)}), because the full run's cost grows with the number of "
              "rotations while the mean run takes a few steps whatever the span. The mean run's cost is nearly "
              "constant until the span needs more than one step. The mean run's error does not fall with the span "
              f"({', '.join(f'{m[5]:.1e}' for m in measured)}; the largest is that of {worst}). It is not the "
              "quadrature: the mean rates on the default grid "
              f"{THERMAL_POINTS_S} × {THERMAL_POINTS_Z} × {THERMAL_POINTS_ORBIT} differ from those on 48 × 24 × 48 by "
              f"{grid_change[(THERMAL_POINTS_S, THERMAL_POINTS_Z, THERMAL_POINTS_ORBIT)]:.1e} at most (24 × 12 × 24: "
              f"{grid_change[(24, 12, 24)]:.1e}; 12 × 6 × 12: {grid_change[(12, 6, 12)]:.1e}), and the spans up to "
              f"{MEAN_STEP_YR:.0f} yr are one smooth step. What is left is the first-order averaging itself "
              "(the osculating start taken as mean elements, the neglected second-order terms) and the reference's "
              "own error (if the full run's error scales with rtol, the 1e-10 column's distance from it puts the "
              "reference's at a few 1e-4).", "",
              f"**Over 10⁶ yr** (with the Sun's gravity precessing h) the mean run is measured: {mean_1e6:.2f} CPU s "
              f"(median of {len(repeats.samples)}, {repeats.min:.2f}–{repeats.max:.2f}, load {load:.1f}), "
              f"{coarse[1]} steps of {MEAN_STEP_YR:.0f} yr, 100 outputs; halving the step changes the changes of S, Z, H "
              f"since t = 0 by at most {stepping:.1e} of their size at any output ({stepping_of_largest:.1e} of the "
              "largest change over the run: the first figure comes from where ΔH passes near zero). The full run over "
              f"10⁶ yr is extrapolated, not run: the matched full run (rtol {matched:.0e}) costs {per_year:.3f} CPU s "
              f"per simulated year over {years} yr, the longest span measured, so {full_1e6 / 3600:.0f} h for 10⁶ yr, "
              f"{ratio:.0f}× the mean run: {verdict}. At the reference tolerance 1e-11 the ratio is "
              f"{reference_s / years * 1e6 / mean_1e6:.0f}×. Matched instead to the 10⁶-yr mean run's step error "
              f"({stepping:.1e}), the full run could run at rtol {loose:.0e} ({looser[loose][1] / years:.3f} CPU s per "
              f"year): {looser[loose][1] / years * 1e6 / mean_1e6:.0f}×. Extrapolated too: that the full run's "
              "relative error of the changes stays what it is over the measured spans (it does across them: the "
              "error columns barely move with the span), and that the mean run's error does too (it stays between "
              f"{min(mean_errors):.1e} and {max(mean_errors):.1e} over the measured spans, without a trend)."]
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the section instead of writing it")
    parser.add_argument("--long", action="store_true",
                        help=f"add the {LONG_SPAN_YR}-yr span to the full-against-mean costs (≈ 5 more minutes)")
    parser.add_argument("--quick", action="store_true", help="fewer degrees, levels and shapes in the shadow section")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    lines = ["### Mass properties", ""] + mass_section()
    lines += ["", "### The recoil torque and its representation", ""] + torque_section()
    lines += ["", "### Self-shadowing", ""] + shadow_section(args.quick)
    lines += ["", "### Mean YORP against the full integration", ""] + mean_section()
    lines += ["", "### Cost at matched accuracy", ""] + cost_section(SPANS_YR + ((LONG_SPAN_YR,) if args.long else ()))
    command = "benchmarks/thermal_validation.py" + (" --long" if args.long else "") + (" --quick" if args.quick else "")
    header = [f"Written by `PYTHONPATH=$PWD python {command}` in "
              f"{time.perf_counter() - start:.0f} s. {machine_line()}", ""]
    text = "\n".join(header + lines)
    if args.no_write:
        print(text)
    else:
        print(write_section("thermal_validation", text, page="thermal.md"))


if __name__ == "__main__":
    main()
