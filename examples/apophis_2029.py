"""
Apophis through the 2029 Earth encounter
========================================

(99942) Apophis through its 2029-04-13 Earth encounter: the tumbling spin before and after.

Initial spin: Pravec et al. 2014 (Icarus 233, 48) — SAM, retrograde, P_ψ = 263 h, P_φ = 27.38 h,
moments 0.61 : 0.965 : 1, angular momentum towards ecliptic (λ, β) = (250°, −75°)
(:func:`spinorbit.data.asteroids.apophis_rotation_state`). Orbit (default ``--orbit published``): the JPL
Horizons solution JPL#218 state at 2021-01-01 TDB (:data:`spinorbit.data.asteroids.APOPHIS_HORIZONS`),
integrated to 2029 with the Sun, planets, Moon and Pluto from DE421 in REBOUND (IAS15, Earth J2 + EIH);
the encounter is then an outcome (printed). ``--orbit geometry`` uses the documented fallback encounter
geometry instead (perigee imposed: 38 000 km from Earth's centre at 7.4 km/s at 2029-04-13 21:46 UTC,
directions from rounded elements; :mod:`spinorbit.data.asteroids`). Torques: Sun, Earth, Moon (degree 2,
point masses), one way.

The rotation *phase* at perigee is not known from the published state, and the outcome depends on it
strongly. ``--phases N`` repeats the run from N phases of the free motion (the published state moved
along its own torque-free motion by k/N of P_ψ before the run starts) and prints the spread.

This script places the published state at the start of its span (``--days`` before perigee), the
convention of the numbers it produced for docs/asteroids.md; with the default ``--days 5`` that is
the state's own epoch, ``APOPHIS_STATE_EPOCH``. ``spinorbit apophis`` and the gallery example
``plot_apophis_2029_phase.py`` run the state from that epoch whatever the span.

Usage::

    python examples/apophis_2029.py                 # ±5 d around perigee, 8 phases (a few seconds)
    python examples/apophis_2029.py --days 60 --phases 48 --output apophis.png
"""
# gallery-arguments: --days 2 --phases 4 --output apophis_2029.png
# sphinx_gallery_thumbnail_path = "gallery/apophis_2029.png"


from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from astropy import units as u

# Run from a checkout without installing (the project does not use editable installs).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from spinorbit import RotationState
from spinorbit.data.asteroids import (
    APOPHIS_2029,
    APOPHIS_HORIZONS,
    apophis_encounter_simulation,
    apophis_rotation_state,
    closest_approach,
    encounter_state,
)
from spinorbit.coupling.one_way import propagate_one_way
from spinorbit.coupling.sampling import sample_from_rebound
from spinorbit.time import tdb_days


def describe(label, row):
    lon, lat = row["pole_lon"].to_value(u.deg), row["pole_lat"].to_value(u.deg)  # ecliptic J2000
    return (f"{label:>7} {row['time'].tdb.iso[:16]} TDB  {row['mode']}  P_psi = {row['P_psi'].to_value(u.h):8.3f} h  "
            f"P_phi = {row['P_phi'].to_value(u.h):7.3f} h  E/E0 = {row['energy_ratio']:.5f}  "
            f"L -> (lambda, beta) = ({lon:6.2f}, {lat:6.2f}) deg")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--days", type=float, default=5.0, help="days before and after perigee (default 5)")
    parser.add_argument("--phases", type=int, default=8, help="rotation phases to try (default 8)")
    parser.add_argument("--tolerance", type=float, default=1e-10, help="sampling tolerance (relative position)")
    parser.add_argument("--rtol", type=float, default=1e-10, help="rotation integrator rtol")
    parser.add_argument("--orbit", choices=("published", "geometry"), default="published",
                        help="Horizons JPL#218 state integrated from 2021 (default) or the fallback encounter geometry")
    parser.add_argument("--output", default="apophis_2029.png", help="PNG to write ('' for none)")
    args = parser.parse_args(argv)

    clock = time.perf_counter()
    t_enc = APOPHIS_2029.time_tdb
    start, end = t_enc - args.days * u.day, t_enc + args.days * u.day
    if args.orbit == "published":
        print(f"Orbit: {APOPHIS_HORIZONS.source}; DE421 planets, IAS15, Earth J2 + EIH + Yarkovsky (A1, A2 of the solution)")
        when, distance_km, speed_km_s = closest_approach(apophis_encounter_simulation("published"), "Apophis", t_enc)
        print(f"  closest approach {when.tdb.iso} TDB, {distance_km:.1f} km from Earth's centre, {speed_km_s:.4f} km/s"
              f" (JPL: 38 012 km, 7.42 km/s, 2029-04-13 21:46)")
    else:
        _, _, details = encounter_state(APOPHIS_2029, return_details=True)
        print("Encounter geometry (documented fallback, not an orbit solution):")
        print(f"  perigee {APOPHIS_2029.distance_km:.0f} km at {APOPHIS_2029.speed_km_s} km/s, {APOPHIS_2029.time.tt.iso[:16]} TT;"
              f" v_inf = {details['v_inf_km_s']:.3f} km/s (rounded elements alone give {details['v_inf_elements_km_s']:.3f})")
    sim = apophis_encounter_simulation(args.orbit)
    samples = sample_from_rebound(sim, "Apophis", start, end, tolerance=args.tolerance)
    when, distance = samples.closest["earth"]
    print(f"  REBOUND/IAS15 run: closest sampled distance {distance * 149_597_870.7:.0f} km; {samples.days.size} samples "
          f"in {samples.passes} passes; interpolation error estimate "
          + ", ".join(f"{n} {e:.1e}" for n, e in zip(samples.names, samples.midpoint_error)))

    published = apophis_rotation_state()
    times = start + np.linspace(0.02, 2 * args.days, 400) * u.day
    table = propagate_one_way(published, start, times, samples, rtol=args.rtol)
    print("\nPublished state (Pravec et al. 2014), rotation phase as constructed, torques Sun+Earth+Moon:")
    print(describe("before", table[0]))
    print(describe("after", table[-1]))
    print(f"  published E/E0 = 1.024 +- 0.013; this state {published.energy_ratio:.4f} (from the moments and periods)")
    print(f"  DOP853: {table.meta['accepted']} steps, rtol {args.rtol:g}")

    afters = []
    if args.phases > 1:
        offsets = np.arange(args.phases) / args.phases * published.periods[0].to_value(u.day)
        quaternions, omegas = published.propagate_torque_free(offsets * u.day)
        for q, w in zip(quaternions, omegas):
            state = RotationState(published.body, q, w)
            result = propagate_one_way(state, start, end, samples, rtol=args.rtol)[-1]
            afters.append((result["P_psi"].to_value(u.h), result["P_phi"].to_value(u.h), result["energy_ratio"],
                           result["mode"]))
        afters_num = np.array([a[:3] for a in afters])
        modes = sorted(set(str(a[3]) for a in afters))
        print(f"\nOver {args.phases} rotation phases (published state moved along its free motion by k/N of P_psi):")
        for name, column in zip(("P_psi [h]", "P_phi [h]", "E/E0"), afters_num.T):
            print(f"  after: {name:9} min {column.min():9.3f}  median {np.median(column):9.3f}  max {column.max():9.3f}")
        print(f"  modes after: {modes}")

    print(f"\nwall time {time.perf_counter() - clock:.1f} s")
    if args.output:
        plot(args.output, table, t_enc, samples, afters)
        print(f"wrote {args.output}")


def plot(path, table, t_enc, samples, afters):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    hours = (table["time"] - t_enc).to_value(u.h)
    fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    axes[0].plot(hours, table["P_psi"].to_value(u.h), label="P_ψ")
    axes[0].set_ylabel("P_ψ [h]")
    axes[1].plot(hours, table["P_phi"].to_value(u.h), color="C1")
    axes[1].set_ylabel("P_φ [h]")
    axes[2].plot(hours, table["energy_ratio"], color="C2")
    axes[2].set_ylabel("E/E0")
    days = samples.days
    earth = np.linalg.norm(samples.states[:, list(samples.names).index("earth"), :3], axis=1) * 149_597_870.7
    distance_axis = axes[2].twinx()
    enc_days, enc_remainder = tdb_days(t_enc)
    distance_axis.semilogy((days - (enc_days + enc_remainder)) * 24, earth, color="0.6", lw=0.8)
    distance_axis.set_ylabel("Earth distance [km]", color="0.5")
    axes[2].set_xlabel("hours from perigee (2029-04-13 21:46 UTC)")
    if afters:
        for value, axis in zip(np.array([a[:3] for a in afters]).T, axes):
            axis.plot(np.full(value.size, hours[-1]), value, "k.", ms=4, label="other phases (end)")
        axes[0].legend(loc="best", fontsize=8)
    fig.suptitle("(99942) Apophis spin through the 2029 encounter (one-way, Sun+Earth+Moon)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
