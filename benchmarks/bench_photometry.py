"""Facet-epochs per second per core of the brightness kernel without shadowing, beside a vectorised numpy evaluation.

Writes the section ``photometry`` of docs/performance.md. One problem for all three: 10⁴ facets (unit
normals uniform on the sphere, areas uniform in (0, 1)) × 10⁴ epochs (Sun and observer directions with
phase angles uniform in 0–90°), the Lommel–Seeliger law (the costliest, one division per facet-epoch):

- spinorbit: :func:`spinorbit.core.photometry.scattering.facet_sum`, the compiled sum over sixteen
  epochs per pass in ``Lanes`` (one thread);
- numpy: μ₀ = S Nᵀ and μ = O Nᵀ by matrix products in blocks of 500 epochs, the law and the mask
  elementwise, the area-weighted sum as a matrix–vector product; BLAS held to one thread, so both
  are per core;
- scalar loop: the same sum compiled with numba one epoch and one facet at a time (what the kernel's
  ``Lanes`` layout is for).

The three agree to 1e-12 (checked each run). Timed as interleaved repeats (median, min–max), after a
warm-up call that also pays numba's compilation. The issue's goal, as a ratio to the peer in the same run: ≥ 20× numpy.

Usage::

    PYTHONPATH=$PWD python benchmarks/bench_photometry.py [--repeat 5] [--no-write] [--size 10000]
"""

from __future__ import annotations

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # one core for numpy's BLAS too
    os.environ[_name] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _report import interleaved_timings, machine_line, ratio_goal, write_section  # noqa: E402

from spinorbit.core.jit import jit  # noqa: E402
from spinorbit.core.photometry.scattering import facet_sum  # noqa: E402

SEED = 20261207
GOAL_RATIO = 20.0
NUMPY_BLOCK = 500


def problem(size, seed=SEED):
    rng = np.random.default_rng(seed)

    def units(n):
        v = rng.normal(size=(n, 3))
        return v / np.linalg.norm(v, axis=1)[:, None]

    normals, areas = units(size), rng.random(size)
    sun = units(size)
    # Observers at phase angles uniform in 0–90° from the Sun, about a random axis perpendicular to it.
    side = np.cross(sun, units(size))
    side /= np.linalg.norm(side, axis=1)[:, None]
    alpha = rng.uniform(0.0, np.pi / 2, size)
    observer = np.cos(alpha)[:, None] * sun + np.sin(alpha)[:, None] * side
    return normals, areas, sun, observer


def numpy_sum(normals, areas, sun, observer):
    out = np.empty(sun.shape[0])
    for start in range(0, sun.shape[0], NUMPY_BLOCK):
        mu0 = sun[start:start + NUMPY_BLOCK] @ normals.T
        mu = observer[start:start + NUMPY_BLOCK] @ normals.T
        with np.errstate(divide="ignore", invalid="ignore"):
            law = np.where((mu > 0) & (mu0 > 0), mu * mu0 / (mu + mu0), 0.0)
        out[start:start + NUMPY_BLOCK] = law @ areas
    return out


@jit
def _scalar_loop(normals, areas, sun, observer, out):
    for j in range(sun.shape[0]):
        total = 0.0
        for k in range(normals.shape[0]):
            mu0 = normals[k, 0] * sun[j, 0] + normals[k, 1] * sun[j, 1] + normals[k, 2] * sun[j, 2]
            mu = normals[k, 0] * observer[j, 0] + normals[k, 1] * observer[j, 1] + normals[k, 2] * observer[j, 2]
            if mu0 > 0.0 and mu > 0.0:
                total += areas[k] * mu * mu0 / (mu + mu0)
        out[j] = total


def scalar_sum(normals, areas, sun, observer):
    out = np.empty(sun.shape[0])
    _scalar_loop(normals, areas, sun, observer, out)
    return out


def measure(repeat, size):
    normals, areas, sun, observer = problem(size)
    calls = [lambda: facet_sum(normals, areas, sun, observer, 1.0, 0.0),
             lambda: numpy_sum(normals, areas, sun, observer),
             lambda: scalar_sum(normals, areas, sun, observer)]
    load_before = os.getloadavg()[0]
    timings, results = interleaved_timings(calls, repeat, warm_up=True)
    load_after = os.getloadavg()[0]
    reference = results[1]
    agreement = max(float(np.max(np.abs(r / reference - 1))) for r in results)
    if agreement > 1e-12:
        raise RuntimeError(f"the three sums disagree by {agreement:.1e}")
    return dict(size=size, timings=timings, agreement=agreement, load=(load_before, load_after))


def markdown(result, repeat):
    size, (kernel, peer, scalar) = result["size"], result["timings"]
    work = float(size) * size
    rate = work / kernel.median
    lines = [f"### Disk-integrated brightness: facet-epochs per second per core (`benchmarks/bench_photometry.py`)", "",
             machine_line(), "",
             f"{size} facets × {size} epochs, Lommel–Seeliger law, no shadowing (convex), one thread each; "
             f"median (min–max) of {len(kernel.samples)} interleaved runs. The three sums agree to "
             f"{result['agreement']:.1e}.", "",
             "| evaluation | time (s) | facet-epochs/s/core | ratio to numpy |", "|---|---|---|---|"]
    for name, timing in (("spinorbit `facet_sum` (Lanes, 16 epochs per pass)", kernel),
                         ("numpy, vectorised (BLAS products, 1 thread)", peer),
                         ("numba scalar loop (one epoch, one facet at a time)", scalar)):
        lines.append(f"| {name} | {timing.text(scale=1, fmt='.4f')} | {work / timing.median:.3g} | "
                     f"{peer.median / timing.median:.1f}× |")
    ratio = peer.median / kernel.median
    verdict = ratio_goal("facet_sum / numpy (facet-epochs per s)", ratio, GOAL_RATIO)
    lines += ["", f"Goal (issue 38, as a ratio to numpy in the same run, issue 39): {verdict} ({rate:.3g} "
              "facet-epochs/s/core here). The 1-minute load average was "
              f"{result['load'][0]:.2f} before and {result['load'][1]:.2f} after (other work shares the two cores)."]
    return "\n".join(lines)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--size", type=int, default=10_000)
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    args = parser.parse_args()
    text = markdown(measure(args.repeat, args.size), args.repeat)
    print(text)
    if not args.no_write:
        print(f"wrote {write_section('photometry', text)}")
