"""
Toutatis 1992–2012
==================

(4179) Toutatis 1992–2012: the tumbling spin under solar and Earth torques, through the 2004 flyby.

Initial state: Takahashi, Busch & Scheeres 2013 (AJ 146, 95, Table 2) at 1992-11-09T17:49:47 UTC
(:func:`spinorbit.data.asteroids.toutatis_rotation_state`; the Euler-angle reading is documented there).
Orbit: Toutatis's published osculating elements (JPL SBDB, epoch 2008-11-27;
:func:`spinorbit.data.asteroids.toutatis_orbit`) integrated with the Sun, planets, Moon and Pluto from
DE421 in REBOUND (IAS15, EIH 1PN, Earth J2); ``--orbit geometry`` takes the older documented
encounter geometry of the 2004-09-29 flyby instead. Torques: Sun and Earth (degree 2), one way. The
orbit's Earth approaches are printed next to the real ones.

Periods are the osculating (instantaneous torque-free) P_ψ, P_φ of the integrated state; they are
compared with Hudson & Ostro 1995 (radar 1992: 5.41 d, 7.35 d) and the Chang'e-2 flyby (2012:
5.38 d, 7.40 d). Those published values have their own uncertainties and model dependencies (a few
hundredths of a day): the comparison is a consistency check, not a test of the integrator.

Usage::

    python examples/toutatis.py                     # full 1992–2012 span (≈ 20–40 s on a shared 2-core machine)
    python examples/toutatis.py --quick             # ±150 d around the 2004 flyby only
    python examples/toutatis.py --quick --phases 24 # and the flyby's effect over 24 rotation phases
"""
# gallery-arguments: --quick --output toutatis.png
# sphinx_gallery_thumbnail_path = "gallery/toutatis.png"


from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.time import Time

# Run from a checkout without installing (the project does not use editable installs).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from spinorbit.data.asteroids import TOUTATIS_2004, TOUTATIS_EPOCH, toutatis_orbit, toutatis_rotation_state
from spinorbit.coupling.one_way import propagate_one_way
from spinorbit.coupling.sampling import sample_from_rebound
from spinorbit.time import tdb_days

KM_PER_AU = 149_597_870.7
#: Real Earth approaches of Toutatis (dates and distances as recalled from JPL close-approach data; for
#: comparison only, not used by the computation).
REAL_APPROACHES = [("1992-12-08", 0.024), ("1996-11-29", 0.035), ("2000-10-31", 0.074),
                   ("2004-09-29", 0.0104), ("2008-11-09", 0.050), ("2012-12-12", 0.046)]
PUBLISHED = {"Hudson & Ostro 1995 (1992 radar)": ("1992-12-08", 5.41, 7.35),
             "Chang'e-2 (2012-12-13 flyby)": ("2012-12-13", 5.38, 7.40)}


def approaches(samples, limit_au=0.2):
    """Local minima of the Earth distance below ``limit_au``: (TDB days, au)."""
    d = np.linalg.norm(samples.states[:, list(samples.names).index("earth"), :3], axis=1)
    inner = np.flatnonzero((d[1:-1] < d[:-2]) & (d[1:-1] <= d[2:]) & (d[1:-1] < limit_au)) + 1
    return [(samples.days[i], d[i]) for i in inner]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only ±150 d around the 2004 flyby")
    parser.add_argument("--end", default="2012-12-31", help="end date (TDB), default 2012-12-31")
    parser.add_argument("--tolerance", type=float, default=1e-9, help="sampling tolerance (relative position)")
    parser.add_argument("--rtol", type=float, default=1e-10, help="rotation integrator rtol")
    parser.add_argument("--phases", type=int, default=0,
                        help="also run the 2004 flyby (±150 d) from N phases of the free motion and print the spread")
    parser.add_argument("--output", default="toutatis.png", help="PNG to write ('' for none)")
    parser.add_argument("--orbit", choices=("elements", "geometry"), default="elements",
                        help="published elements (default) or the documented 2004-flyby geometry")
    args = parser.parse_args(argv)

    clock = time.perf_counter()
    state = toutatis_rotation_state()
    p_psi, p_phi = state.periods
    print(f"Takahashi et al. 2013 state at {TOUTATIS_EPOCH.iso} UTC: {state.mode}, torque-free "
          f"P_psi = {p_psi.to_value(u.day):.4f} d, P_phi = {p_phi.to_value(u.day):.4f} d (anchors: 5.369 / 7.412)")

    flyby = TOUTATIS_2004.time_tdb
    sim = toutatis_orbit(args.orbit).simulation
    if args.quick:
        start, end, epoch = flyby - 150 * u.day, flyby + 150 * u.day, None
    else:
        start, end, epoch = TOUTATIS_EPOCH, Time(args.end, scale="tdb"), TOUTATIS_EPOCH
    samples = sample_from_rebound(sim, "Toutatis", start, end, perturbers=("sun", "earth"), tolerance=args.tolerance)
    print(f"REBOUND/IAS15 orbit {start.tdb.iso[:10]} .. {end.tdb.iso[:10]}: {samples.days.size} samples in "
          f"{samples.passes} passes, interpolation error estimate "
          + ", ".join(f"{n} {e:.1e}" for n, e in zip(samples.names, samples.midpoint_error)))
    print("Earth approaches < 0.2 au in this orbit (real ones, as recalled: "
          + ", ".join(f"{d} {a} au" for d, a in REAL_APPROACHES) + "):")
    for day, distance in approaches(samples):
        print(f"  {Time(day + 2451545.0, format='jd', scale='tdb').iso[:16]} TDB  {distance:.5f} au "
              f"({distance * KM_PER_AU:,.0f} km)")

    if epoch is None:
        # The quick run starts from the published state as if it held at start: the free motion
        # between 1992 and 2004 (and its torques) is skipped, so only the flyby's effect is meaningful.
        epoch = start
    # Stop a microsecond short of the sampled end: start + (end − start) can round past it.
    times = start + np.linspace(0.5, (end - start).to_value(u.day) - 1e-6, 1500 if not args.quick else 300) * u.day
    table = propagate_one_way(state, epoch, times, samples, rtol=args.rtol)
    print(f"DOP853: {table.meta['accepted']} steps, rtol {args.rtol:g}")

    days = np.array([tdb_days(t)[0] + tdb_days(t)[1] for t in table["time"]])
    flyby_day = sum(tdb_days(flyby))

    def mean_periods(centre_day, half_width=60.0):
        mask = np.abs(days - centre_day) <= half_width
        return table["P_psi"][mask].to_value(u.day).mean(), table["P_phi"][mask].to_value(u.day).mean()

    print("\nOsculating periods, means over ±60 d windows:")
    before = mean_periods(flyby_day - 90)
    after = mean_periods(flyby_day + 90)
    print(f"  before the 2004 flyby: P_psi = {before[0]:.4f} d, P_phi = {before[1]:.4f} d")
    print(f"  after  the 2004 flyby: P_psi = {after[0]:.4f} d, P_phi = {after[1]:.4f} d "
          f"(change {after[0] - before[0]:+.4f} d, {after[1] - before[1]:+.4f} d)")
    if not args.quick:
        for label, (date, pub_psi, pub_phi) in PUBLISHED.items():
            centre = sum(tdb_days(Time(date, scale="tdb")))
            if days.min() <= centre <= days.max():
                ours = mean_periods(centre)
                print(f"  {label}: published {pub_psi:.2f} / {pub_phi:.2f} d; here {ours[0]:.4f} / {ours[1]:.4f} d "
                      f"(difference {ours[0] - pub_psi:+.3f} / {ours[1] - pub_phi:+.3f} d)")
    if args.phases > 1:
        flyby_phases(state, flyby, samples, args.phases, args.rtol)
    print(f"\nwall time {time.perf_counter() - clock:.1f} s")
    if args.output:
        plot(args.output, table, samples)
        print(f"wrote {args.output}")


def flyby_phases(state, flyby, samples, phases, rtol):
    """ΔP_ψ, ΔP_φ across the 2004 flyby from ``phases`` attitudes: the published state moved along its
    own free motion by k/N of P_φ and started 150 d before the flyby (the phase at the flyby is what
    the published 1992 state, propagated 12 years, fixes only as well as its periods are known)."""
    from spinorbit import RotationState

    start = flyby - 150 * u.day
    offsets = np.arange(phases) / phases * state.periods[1].to_value(u.day)
    quaternions, omegas = state.propagate_torque_free(offsets * u.day)
    changes = []
    for q, w in zip(quaternions, omegas):
        table = propagate_one_way(RotationState(state.body, q, w), start,
                                  start + np.linspace(1.0, 299.0, 300) * u.day, samples, rtol=rtol)
        days = np.linspace(1.0, 299.0, 300)
        before = days < 100
        after = days > 200
        changes.append([table["P_psi"][after].to_value(u.day).mean() - table["P_psi"][before].to_value(u.day).mean(),
                        table["P_phi"][after].to_value(u.day).mean() - table["P_phi"][before].to_value(u.day).mean()])
    changes = np.array(changes)
    print(f"\n2004 flyby over {phases} rotation phases (means over 100 d before/after):")
    for name, column in zip(("dP_psi", "dP_phi"), changes.T):
        print(f"  {name}: min {column.min():+.5f} d  median {np.median(column):+.5f} d  max {column.max():+.5f} d")


def plot(path, table, samples):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    years = table["time"].tdb.decimalyear
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    axes[0].plot(years, table["P_psi"].to_value(u.day), lw=0.8)
    axes[0].set_ylabel("P_ψ [d]")
    axes[1].plot(years, table["P_phi"].to_value(u.day), lw=0.8, color="C1")
    axes[1].set_ylabel("P_φ [d]")
    for label, (date, pub_psi, pub_phi) in PUBLISHED.items():
        year = Time(date, scale="tdb").decimalyear
        if years.min() <= year <= years.max():
            axes[0].plot(year, pub_psi, "ks", ms=5)
            axes[1].plot(year, pub_phi, "ks", ms=5)
            axes[0].annotate(label, (year, pub_psi), fontsize=7, xytext=(3, 3), textcoords="offset points")
    earth = np.linalg.norm(samples.states[:, list(samples.names).index("earth"), :3], axis=1)
    sample_years = Time(samples.days + 2451545.0, format="jd", scale="tdb").decimalyear
    axes[2].semilogy(sample_years, earth, color="0.4", lw=0.8)
    axes[2].set_ylabel("Earth distance [au]")
    axes[2].set_xlabel("year (TDB)")
    fig.suptitle("(4179) Toutatis: osculating periods under Sun + Earth torques (one-way)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
