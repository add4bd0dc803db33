"""How exact the photometry kernels are, each against an independent reference.

Regenerates the section "accuracy_photometry" of ``docs/photometry.md``:

1. the closed forms (Lommel–Seeliger ellipsoid at any geometry, Muinonen & Lumme 2015; Lambertian
   ellipsoid at opposition) against the 25-digit mpmath quadratures of ``tests/_photometry_reference.py``
   (read from ``tests/data/photometry_ellipsoid_reference.json``, which that script writes);
2. the facet model of the ellipsoid (1.3, 0.9, 0.6) km against them, icosphere levels 3–7;
3. the ray-traced facet sum of two non-convex shapes against brute force (every sample point's rays
   against every triangle, numpy) and an L-shaped block's shadow against its closed form.

Run: ``PYTHONPATH=$PWD python benchmarks/accuracy_photometry.py [--no-write]`` (≈ 1 min).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
from astropy import units as u

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from _report import machine_line, write_section  # noqa: E402
from _photometry_reference import brute_force_brightness, l_shape  # noqa: E402

from spinorbit.core.photometry.ellipsoid import lambert_ellipsoid_at_opposition, lommel_seeliger_ellipsoid  # noqa: E402
from spinorbit.photometry import brightness  # noqa: E402
from spinorbit.shape import ellipsoid_shape, gaussian_random_sphere  # noqa: E402

AXES = (1.3, 0.9, 0.6)
LEVELS = (3, 4, 5, 6, 7)


def unit(vectors):
    vectors = np.atleast_2d(np.asarray(vectors, dtype=float))
    return vectors / np.linalg.norm(vectors, axis=1)[:, None]


def closed_forms():
    cases = json.loads((ROOT / "tests" / "data" / "photometry_ellipsoid_reference.json").read_text())["cases"]
    worst = {}
    for case in cases:
        sun, observer = np.array([case["sun"]]), np.array([case["observer"]])
        if case["law"] == "lommel-seeliger":
            value = lommel_seeliger_ellipsoid(case["semi_axes"], sun, observer)[0]
        else:
            value = lambert_ellipsoid_at_opposition(case["semi_axes"], observer)[0]
        error = abs(value / float(case["brightness"]) - 1)
        count, largest = worst.get(case["law"], (0, 0.0))
        worst[case["law"]] = (count + 1, max(largest, error))
    return worst


def convergence():
    sun, observer = unit([0.7, -0.2, 0.5]), unit([0.3, 0.5, 0.8])
    exact_ls = lommel_seeliger_ellipsoid(AXES, sun, observer)[0]
    exact_lambert = lambert_ellipsoid_at_opposition(AXES, observer)[0]
    rows = []
    for level in LEVELS:
        shape = ellipsoid_shape(AXES * u.km, level)
        ls = brightness(shape, sun, observer)[0].to_value(u.km**2)
        lambert = brightness(shape, observer, observer, law="lambert")[0].to_value(u.km**2)
        rows.append((level, len(shape), ls / exact_ls - 1, lambert / exact_lambert - 1))
    return rows


def shadowing():
    rng = np.random.default_rng(5)
    sun, observer = unit(rng.normal(size=(8, 3))), unit(rng.normal(size=(8, 3)))
    rows = []
    for name, shape in (("L-shaped block (136 facets)", l_shape()),
                        ("Gaussian random sphere σ = 0.35 (320 facets)",
                         gaussian_random_sphere(1.0 * u.km, 0.35, seed=11, subdivisions=2))):
        traced = brightness(shape, sun, observer, law="kaasalainen", shadow_samples=2).value
        reference = brute_force_brightness(shape, sun, observer, 2, (1.0, 0.1))
        unshadowed = brightness(shape, sun, observer, law="kaasalainen", shadowing="none").value
        lit = reference > 0
        rows.append((name, float(np.max(np.abs(traced[lit] / reference[lit] - 1))),
                     float(np.max(unshadowed[lit] / reference[lit] - 1))))
    elevation = math.atan(2.0)
    mu0 = math.sin(elevation)
    value = brightness(l_shape(), [[-math.cos(elevation), 0.0, mu0]], [[0.0, 0.0, 1.0]], shadow_samples=3)[0].value
    return rows, abs(value / (24.0 * mu0 / (1.0 + mu0)) - 1)


def markdown():
    worst = closed_forms()
    rows = convergence()
    shadow_rows, l_error = shadowing()
    lines = ["### The kernels against independent references (`benchmarks/accuracy_photometry.py`)", "",
             machine_line(), "",
             "Closed forms against 25-digit mpmath quadratures of the surface integral "
             "(`tests/_photometry_reference.py`):", "",
             "| closed form | geometries | largest relative error |", "|---|---|---|"]
    names = {"lommel-seeliger": "Lommel–Seeliger ellipsoid, any geometry", "lambert": "Lambertian ellipsoid at opposition"}
    for law, (count, error) in worst.items():
        lines.append(f"| {names[law]} | {count} | {error:.1e} |")
    lines += ["", f"Facet model of the ellipsoid {AXES} km (icosphere level k, 20·4^k facets) against the closed forms "
              "(LS: Sun (0.7, −0.2, 0.5), observer (0.3, 0.5, 0.8), normalised; Lambert: opposition along the latter):",
              "", "| level | facets | Lommel–Seeliger error | Lambert error |", "|---|---|---|---|"]
    for level, facets, ls, lambert in rows:
        lines.append(f"| {level} | {facets} | {ls:.2e} | {lambert:.2e} |")
    lines += ["", "Self-shadowing (Kaasalainen law, c = 0.1, 2² sample points per facet, 8 random geometries) against "
              "brute-force ray casting; the last column is how much brighter the sum is without shadows:", "",
              "| shape | largest relative difference | without shadowing |", "|---|---|---|"]
    for name, error, unshadowed in shadow_rows:
        lines.append(f"| {name} | {error:.1e} | +{unshadowed:.1%} |")
    lines += ["", f"The L-shaped block's tower casting a 2 × 4 km shadow on its floor (Sun at cot e = 1/2, observer at "
              f"the zenith) against the closed form 24 km² · μ₀/(1 + μ₀): relative error {l_error:.1e}."]
    return "\n".join(lines)


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/photometry.md")
    args = parser.parse_args()
    text = markdown()
    print(text)
    if not args.no_write:
        print(f"wrote {write_section('accuracy_photometry', text, page='photometry.md')}")
