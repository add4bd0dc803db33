"""Speed of the elliptic kernels beside scipy, on the same inputs, in one process.

Scalar rows: ns per call inside a numba loop (constants precomputed once per m, as the
canonical-element code will do); scipy is called through ``scipy.special.cython_special`` from
numba. Vectorized rows: ns per element of the public wrappers and of the scipy ufuncs.
Writes its table into ``docs/performance.md`` (section ``bench_elliptic``; ``--no-write``: print only).
Run: ``python benchmarks/bench_elliptic.py`` from the repository root.
"""

import ctypes
import sys
from pathlib import Path

import numba
import numpy as np
import scipy
import scipy.special as sc
from numba.extending import get_cython_function_address

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _report import Timing, interleaved_timings, machine_line, write_section  # noqa: E402

from spinorbit import special  # noqa: E402
from spinorbit.core.math.complete_agm import complete_k_pi_dd  # noqa: E402
from spinorbit.core.math import elliptic as E  # noqa: E402
from spinorbit.core.math.elliptic_integrals import complete_k_pi  # noqa: E402

N = 200_000
REPEATS = 7
M, MC = 0.7, 0.3  # a typical short-axis-mode parameter (1 − 0.7 is exact: 0.3 is mc's double)
F = 2.5  # f = (a − b)/(b − c) of a moderately triaxial body
GOALS = {"sncndn": 80.0, "pn(u, −f|m)": 250.0, "pn(u, m|m)": 250.0}

# scipy scalar functions through cython_special (ctypes pointers: numba cannot cache these loops,
# so the benchmark's own loops use plain njit)
_d = ctypes.c_double
_p = ctypes.POINTER(ctypes.c_double)
_cs = "scipy.special.cython_special"
scipy_ellipj = ctypes.CFUNCTYPE(None, _d, _d, _p, _p, _p, _p)(get_cython_function_address(_cs, "ellipj"))
scipy_ellipkinc = ctypes.CFUNCTYPE(_d, _d, _d, ctypes.c_int)(get_cython_function_address(_cs, "ellipkinc"))
scipy_elliprf = ctypes.CFUNCTYPE(_d, _d, _d, _d, ctypes.c_int)(
    get_cython_function_address(_cs, "__pyx_fuse_1elliprf")
)
scipy_elliprj = ctypes.CFUNCTYPE(_d, _d, _d, _d, _d, ctypes.c_int)(
    get_cython_function_address(_cs, "__pyx_fuse_1elliprj")
)


@numba.njit
def loop_sncndn(u, mk):
    total = 0.0
    for x in u:
        s, c, d = E.sncndn_k(x, mk)
        total += s + c + d
    return total


@numba.njit
def loop_am(u, mk):
    total = 0.0
    for x in u:
        total += E.am_k(x, mk)
    return total


@numba.njit
def loop_ellipk(m, mc):
    total = 0.0
    for i in range(m.size):
        total += E.ellipk(m[i], mc[i])
    return total


@numba.njit
def loop_complete_dd(f, mc):
    total = 0.0
    for i in range(mc.size):
        k_hi, _, pi_hi, _ = complete_k_pi_dd(f, 0.0, mc[i], 0.0)
        total += k_hi + pi_hi
    return total


@numba.njit
def loop_complete(f, mc):
    total = 0.0
    for i in range(mc.size):
        k, pi = complete_k_pi(f, mc[i])
        total += k + pi
    return total


@numba.njit
def loop_ellipf(phi, mk):
    total = 0.0
    for x in phi:
        total += E.ellipf_k(x, mk)
    return total


@numba.njit
def loop_ellippi(phi, mk, nk):
    total = 0.0
    for x in phi:
        total += E.ellippi_k(x, mk, nk)
    return total


@numba.njit
def loop_pn(u, mk, pk):
    total = 0.0
    for x in u:
        total += E.pn_k(x, mk, pk)
    return total


@numba.njit
def loop_rf(x, y, z):
    total = 0.0
    for i in range(x.size):
        total += E.rf(x[i], y[i], z[i])
    return total


@numba.njit
def loop_rj(x, y, z, p):
    total = 0.0
    for i in range(x.size):
        total += E.rj(x[i], y[i], z[i], p[i])
    return total


@numba.njit
def loop_scipy_ellipj(u, m):
    out = np.empty(4)
    total = 0.0
    for x in u:
        scipy_ellipj(x, m, out[0:].ctypes, out[1:].ctypes, out[2:].ctypes, out[3:].ctypes)
        total += out[0] + out[1] + out[2]
    return total


@numba.njit
def loop_scipy_ellipkinc(phi, m):
    total = 0.0
    for x in phi:
        total += scipy_ellipkinc(x, m, 0)
    return total


@numba.njit
def loop_scipy_elliprf(x, y, z):
    total = 0.0
    for i in range(x.size):
        total += scipy_elliprf(x[i], y[i], z[i], 0)
    return total


@numba.njit
def loop_scipy_elliprj(x, y, z, p):
    total = 0.0
    for i in range(x.size):
        total += scipy_elliprj(x[i], y[i], z[i], p[i], 0)
    return total


def ns_per_element(function, *args, count=N):
    """Timing (ns per element) of REPEATS calls after a warm-up call (compilation)."""
    (timing,), _ = interleaved_timings([lambda: function(*args)], REPEATS, warm_up=True)
    return Timing(tuple(t / count * 1e9 for t in timing.samples))


def _ns(timing):
    return f"{timing.median:.0f} ({timing.min:.0f}–{timing.max:.0f})"


#: ``--quick`` (benchmarks/run_all.py's smoke run): inputs and repeats, print only.
QUICK_N, QUICK_REPEATS = 2_000, 2


def main():
    global N, REPEATS
    quick = "--quick" in sys.argv[1:]
    if quick:
        N, REPEATS = QUICK_N, QUICK_REPEATS
    rng = np.random.default_rng(2024)
    u = rng.uniform(-50.0, 50.0, N)
    phi = rng.uniform(-1.5, 1.5, N)  # scipy's ellipkinc reduces φ too; keep both in one range
    xs, ys, zs, ps = (rng.uniform(0.1, 10.0, N) for _ in range(4))
    m_arr = rng.uniform(0.0, 0.99, N)
    mk = E.parameter_constants(M, MC)
    nk = E.characteristic_constants(-F, M, MC)
    pk_f = E.pn_constants(-F, M, MC)
    pk_m = E.pn_constants(M, M, MC)

    rows = []  # (what, spinorbit ns, scipy name, scipy ns, goal)
    rows.append(("sncndn (sn, cn, dn)", ns_per_element(loop_sncndn, u, mk), "ellipj",
                 ns_per_element(loop_scipy_ellipj, u, M), GOALS["sncndn"]))
    rows.append(("am", ns_per_element(loop_am, u, mk), "ellipj (ph)",
                 ns_per_element(loop_scipy_ellipj, u, M), None))
    rows.append(("K (own AGM, double-double)", ns_per_element(loop_ellipk, m_arr, 1.0 - m_arr), "", None, None))
    rows.append(("K and Π(−f|m) together, compensated AGM (~1e-30; flow set-up)",
                 ns_per_element(loop_complete_dd, F, 1.0 - m_arr), "", None, None))
    rows.append(("K and Π(−f|m) together, double AGM", ns_per_element(loop_complete, F, 1.0 - m_arr), "", None, None))
    rows.append(("F(φ|m)", ns_per_element(loop_ellipf, phi, mk), "ellipkinc",
                 ns_per_element(loop_scipy_ellipkinc, phi, M), None))
    rows.append(("Π(φ, −f|m)", ns_per_element(loop_ellippi, phi, mk, nk), "", None, None))
    rows.append(("pn(u, −f|m)", ns_per_element(loop_pn, u, mk, pk_f), "", None, GOALS["pn(u, −f|m)"]))
    rows.append(("pn(u, m|m)", ns_per_element(loop_pn, u, mk, pk_m), "", None, GOALS["pn(u, m|m)"]))
    rows.append(("R_F", ns_per_element(loop_rf, xs, ys, zs), "elliprf",
                 ns_per_element(loop_scipy_elliprf, xs, ys, zs), None))
    rows.append(("R_J", ns_per_element(loop_rj, xs, ys, zs, ps), "elliprj",
                 ns_per_element(loop_scipy_elliprj, xs, ys, zs, ps), None))

    vector_rows = [
        ("ellipj(u, m)", ns_per_element(special.ellipj, u, M), "ellipj",
         ns_per_element(sc.ellipj, u, M), "no slower than scipy"),
        ("ellipf(φ, m)", ns_per_element(special.ellipf, phi, M), "ellipkinc",
         ns_per_element(sc.ellipkinc, phi, M), None),
        ("pn(u, −f, m)", ns_per_element(special.pn, u, -F, M), "", None, None),
        ("Carlson R_F (numba kernel, loop)", ns_per_element(loop_rf, xs, ys, zs), "elliprf",
         ns_per_element(sc.elliprf, xs, ys, zs), None),
        ("Carlson R_J (numba kernel, loop)", ns_per_element(loop_rj, xs, ys, zs, ps), "elliprj",
         ns_per_element(sc.elliprj, xs, ys, zs, ps), None),
    ]

    def table(title, entries, goal_is_ns):
        lines = [f"**{title}**", "",
                 "| function | spinorbit ns | scipy peer | scipy ns | spinorbit/scipy | goal | met |",
                 "|---|---:|---|---:|---:|---|---|"]
        for what, ours_timing, peer, theirs_timing, goal in entries:
            ours = ours_timing.median
            theirs = theirs_timing.median if theirs_timing else None
            ratio = f"{ours / theirs:.2f}" if theirs else "—"
            theirs_text = _ns(theirs_timing) if theirs else "—"
            if goal is None:
                goal_text, met = "—", "—"
            elif goal_is_ns:
                goal_text, met = f"≤ {goal:.0f} ns", "pass" if ours <= goal else "**miss**"
            else:
                goal_text, met = goal, "pass" if ours <= theirs else "**miss**"
            what = what.replace("|", "\\|")  # a bare | would split the Markdown cell
            lines.append(f"| {what} | {_ns(ours_timing)} | {peer or '—'} | {theirs_text} | {ratio} | {goal_text} | {met} |")
        return "\n".join(lines)

    markdown = "\n".join([
        "## Elliptic functions (`benchmarks/bench_elliptic.py`)",
        "",
        machine_line() + f" scipy {scipy.__version__}. One thread; median (min–max) of {REPEATS} runs over "
        f"{N:,} inputs; m = {M}, f = {F}, u uniform in [−50, 50], φ in [−1.5, 1.5].",
        "",
        table("Scalar kernels in a numba loop (per-m constants precomputed; scipy through "
              "cython_special)", rows, True),
        "",
        table("Vectorized, per element (public wrappers vs scipy ufuncs)", vector_rows, False),
        "",
        "scipy has no Π and no pn (scipy issue 4452), hence the empty peer cells; its `ellipj` "
        "also returns NaN for m > 1 and loses accuracy near m = 1 (see `docs/elliptic.md`).",
    ])
    print(markdown)
    if not quick and "--no-write" not in sys.argv[1:]:
        write_section("bench_elliptic", markdown)


if __name__ == "__main__":
    main()
