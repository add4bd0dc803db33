"""Largest errors of spinorbit.special against mpmath (40 digits), region by region.

Regenerates the table "Largest errors over random samples" in ``docs/elliptic.md``, so the page
never quotes errors of an older version of the kernels. Inputs are drawn with a fixed seed from
the regions the tests cover (log-uniform in mc, f and |u| where those span decades); the reference
is ``tests/_elliptic_reference.py``, fed the exact double inputs.

Run: ``python benchmarks/accuracy_elliptic.py [--samples N]`` (default 300 per region, ≈ 1 min).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import mpmath as mp
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import _elliptic_reference as ref  # noqa: E402
from _report import machine_line, write_section  # noqa: E402

from spinorbit import special  # noqa: E402

RNG_SEED = 20261122


def _log_uniform(rng, low, high, n):
    return np.exp(rng.uniform(np.log(low), np.log(high), n))


def _parameters_below_one(rng, n):
    """(m, mc) pairs with mc log-uniform in [1e-15, 1]: the caller's exact mc, as the tests pass it."""
    mc = _log_uniform(rng, 1e-15, 1.0, n)
    return 1.0 - mc, mc


def _parameters_above_one(rng, n):
    m = 1.0 + _log_uniform(rng, 1e-15, 1e6, n)
    return m, 1.0 - m


def _abs_error_sncndn(u, m, mc):
    s, c, d = special.ellipj(u, m, mc=mc)
    exact = ref.sncndn(u, m, mc)
    return max(float(abs(mp.mpf(x) - e)) for x, e in zip((s, c, d), exact))


def sncndn_below_one(rng, n):
    m, mc = _parameters_below_one(rng, n)
    u = rng.uniform(0.0, 1.0, n) * np.array([float(special.ellipk(a, mc=b)) for a, b in zip(m, mc)])
    return max(_abs_error_sncndn(*args) for args in zip(u, m, mc))


def sncndn_above_one(rng, n):
    m, mc = _parameters_above_one(rng, n)
    u = rng.choice([-1.0, 1.0], n) * _log_uniform(rng, 1e-3, 1e6, n)
    return max(_abs_error_sncndn(*args) for args in zip(u, m, mc))


def sncndn_at_one(rng, n):
    u = rng.uniform(-40.0, 40.0, n)
    return max(_abs_error_sncndn(x, 1.0, 0.0) for x in u)


def am_above_one(rng, n):
    m, mc = _parameters_above_one(rng, n)
    u = rng.uniform(-50.0, 50.0, n)
    return max(float(abs(special.am(x, a, mc=b) - ref.amplitude(x, a, b))) for x, a, b in zip(u, m, mc))


def k_above_one(rng, n):
    m, _ = _parameters_above_one(rng, n)
    return max(ref.relative_error(special.ellipk(a), mp.re(mp.ellipk(mp.mpf(a)))) for a in m)


def f_below_one(rng, n):
    m, mc = _parameters_below_one(rng, n)
    phi = rng.choice([-1.0, 1.0], n) * _log_uniform(rng, 1e-3, 1e6, n)
    return max(ref.relative_error(special.ellipf(p, a, mc=b), mp.ellipf(mp.mpf(p), ref.exact_parameter(a, b)))
               for p, a, b in zip(phi, m, mc))


def pi_negative_characteristic(rng, n):
    m, mc = _parameters_below_one(rng, n)
    f = _log_uniform(rng, 1e-6, 1e30, n)
    phi = rng.uniform(-1.5, 1.5, n)
    return max(ref.relative_error(special.ellippi(-g, p, a, mc=b), ref.ellippi(-mp.mpf(g), p, ref.exact_parameter(a, b)))
               for p, a, b, g in zip(phi, m, mc, f))


def pi_n_equal_m(rng, n):
    m, mc = _parameters_below_one(rng, n)
    phi = rng.uniform(-1.5, 1.5, n)
    exact_m = [ref.exact_parameter(a, b) for a, b in zip(m, mc)]
    return max(ref.relative_error(special.ellippi(a, p, a, mc=b), ref.ellippi(mm, p, mm))
               for p, a, b, mm in zip(phi, m, mc, exact_m))


def pn_negative_characteristic(rng, n):
    m, mc = _parameters_below_one(rng, n // 2)
    m2, mc2 = _parameters_above_one(rng, n - n // 2)
    m, mc = np.concatenate([m, m2]), np.concatenate([mc, mc2])
    f = _log_uniform(rng, 1e-6, 1e6, n)
    u = rng.choice([-1.0, 1.0], n) * _log_uniform(rng, 1e-3, 1e6, n)
    return max(ref.relative_error(special.pn(x, -g, a, mc=b), ref.pn(x, -mp.mpf(g), a, b))
               for x, g, a, b in zip(u, f, m, mc))


def pn_n_equal_m(rng, n):
    m, mc = _parameters_below_one(rng, n)
    u = rng.uniform(-20.0, 20.0, n)
    return max(ref.relative_error(special.pn(x, a, a, mc=b), ref.pn(x, ref.exact_parameter(a, b), a, b))
               for x, a, b in zip(u, m, mc))


REGIONS = (
    ("sn, cn, dn", "m < 1 (mc log-uniform in [1e-15, 1]), u ∈ [0, K]", "abs", sncndn_below_one),
    ("sn, cn, dn", "m > 1 (m − 1 log-uniform in [1e-15, 1e6]), |u| ∈ [1e-3, 1e6]", "abs", sncndn_above_one),
    ("sn, cn, dn", "m = 1, |u| ≤ 40", "abs", sncndn_at_one),
    ("am", "m > 1, |u| ≤ 50", "abs", am_above_one),
    ("K", "m > 1", "rel", k_above_one),
    ("F", "m < 1, |φ| ∈ [1e-3, 1e6]", "rel", f_below_one),
    ("Π(φ, −f | m)", "f ∈ [1e-6, 1e30], m < 1, |φ| ≤ 1.5", "rel", pi_negative_characteristic),
    ("Π(φ, m | m)", "m < 1, |φ| ≤ 1.5", "rel", pi_n_equal_m),
    ("pn(u, −f | m)", "f ∈ [1e-6, 1e6], m < 1 and m > 1, |u| ∈ [1e-3, 1e6]", "rel", pn_negative_characteristic),
    ("pn(u, m | m)", "m < 1, |u| ≤ 20", "rel", pn_n_equal_m),
)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--samples", type=int, default=300, help="random inputs per region (default 300)")
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/elliptic.md")
    parser.add_argument("--quick", action="store_true", help="5 inputs per region, print only (smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.samples, args.no_write = 5, True
    rng = np.random.default_rng(RNG_SEED)
    rows = []
    for function, region, kind, measure in REGIONS:
        error = measure(rng, args.samples)
        cells = [text.replace("|", "\\|") for text in (function, region)]  # '|' would split the cell
        rows.append(f"| {cells[0]} | {cells[1]} | {error:.1e} {kind} |")
        print(rows[-1], flush=True)
    markdown = "\n".join([
        "### Largest errors over random samples (`benchmarks/accuracy_elliptic.py`)",
        "",
        f"{machine_line()} {args.samples} inputs per region, seed {RNG_SEED}, mpmath at 40 digits.",
        "",
        "| function | region | max error |",
        "|---|---|---|",
        *rows,
    ])
    print(markdown)
    if not args.no_write:
        write_section("accuracy_elliptic", markdown, page="elliptic.md")


if __name__ == "__main__":
    main()
