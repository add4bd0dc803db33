"""Toutatis 1992–2012 on its published-elements orbit: the Earth approaches and the spin, regenerated.

Writes the section ``toutatis_validation`` of docs/asteroids.md and docs/validation.md (the numbers
there come from this script only):

1. the Earth approaches 1992–2013 of the orbit from each published element set
   (:data:`spinorbit.data.asteroids.TOUTATIS_ELEMENT_SETS`, integrated among DE421's planets with
   EIH 1PN and Earth J2), next to the published ones (``../shared/data/toutatis_orbit.json``);
2. the Takahashi et al. (2013) spin state propagated as a planned Scene from its epoch,
   1992-11-09, to 2013-06-01 on the default (2008) orbit under the Sun's and Earth's torques: the
   osculating periods around the radar campaigns and flybys against the published ones, and what
   each Earth approach changes.

Usage::

    PYTHONPATH=$PWD python benchmarks/toutatis_validation.py            # ≈ 1–2 min
    PYTHONPATH=$PWD python benchmarks/toutatis_validation.py --no-write # print only
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.time import Time

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import machine_line, write_section  # noqa: E402

from spinorbit.data.asteroids import (  # noqa: E402
    TOUTATIS_APPROACHES,
    TOUTATIS_ELEMENT_SETS,
    TOUTATIS_EPOCH,
    toutatis_rotation_state,
)
from spinorbit.scene import Scene  # noqa: E402

#: Published periods (anchors): Hudson & Ostro 1995 (1992 radar), Chang'e-2 (2012-12-13 flyby).
PUBLISHED_PERIODS = (("Hudson & Ostro 1995, 1992 radar", "1992-12-08", 5.41, 7.35),
                     ("Chang'e-2 flyby 2012-12-13", "2012-12-13", 5.38, 7.40))
#: The run ends far enough after the 2012 approach for its 90-d "after" window.
END = Time("2013-06-01", scale="tdb")
WINDOW_DAYS = 60.0


def approach_rows(tables):
    """Markdown rows: each published approach against the nearest one of each element set's orbit."""
    rows = ["| published (date, au) | 2008 elements: time (TDB), au | 2016 elements: time (TDB), au | "
            "2008 − published | 2008 − 2016 |", "|---|---|---|---:|---:|"]
    for date, distance, time_of_day, _status in TOUTATIS_APPROACHES:
        picked = {}
        for key, table in tables.items():
            k = int(np.argmin(np.abs((table["time"] - Time(date, scale="tdb")).to_value(u.day))))
            picked[key] = (table["time"][k], table["distance"][k].to_value(u.au))
        (t08, d08), (t16, d16) = picked["2008"], picked["2016"]
        published = f"{date}{' ' + time_of_day if time_of_day else ''}, {distance}"
        if time_of_day:
            when = Time(f"{date}T{time_of_day.split()[0]}:00", scale="utc")
            timing = f"{(t08 - when).to_value(u.hour):+.1f} h, "
        else:
            timing = ""
        rows.append(f"| {published} | {t08.iso[:16]}, {d08:.5f} | {t16.iso[:16]}, {d16:.5f} | "
                    f"{timing}{100 * (d08 / distance - 1):+.1f} % | {(t08 - t16).to_value(u.hour):+.1f} h, "
                    f"{100 * (d08 / d16 - 1):+.1f} % |")
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--no-write", action="store_true", help="print only, leave docs/ alone")
    parser.add_argument("--n-times", type=int, default=2000)
    args = parser.parse_args(argv)
    clock = time.perf_counter()
    start = TOUTATIS_EPOCH.tdb
    tables = {key: elements.orbit().approaches("earth", Time("1992-06-01", scale="tdb"), Time("2013-06-01", scale="tdb"))
              for key, elements in TOUTATIS_ELEMENT_SETS.items()}
    approach_seconds = time.perf_counter() - clock

    orbit = TOUTATIS_ELEMENT_SETS["2008"].orbit()
    times = start + np.linspace(1.0, (END - start).to_value(u.day), args.n_times) * u.day
    scene = Scene(toutatis_rotation_state(), start, times, perturbers=("sun", "earth"), orbit=orbit,
                  tolerance=1 * u.arcsec)
    run_clock = time.perf_counter()
    result = scene.run()
    run_seconds = time.perf_counter() - run_clock
    table = result.table
    days = (table["time"] - start).to_value(u.day)

    def mean_periods(centre):
        mask = np.abs(days - (centre - start).to_value(u.day)) <= WINDOW_DAYS
        return table["P_psi"][mask].to_value(u.day).mean(), table["P_phi"][mask].to_value(u.day).mean()

    p_psi0, p_phi0 = (p.to_value(u.day) for p in toutatis_rotation_state().periods)
    lines = [machine_line(),
             f"`PYTHONPATH=$PWD python benchmarks/toutatis_validation.py` (approaches {approach_seconds:.1f} s, "
             f"spin run {run_seconds:.1f} s). Orbit: {orbit.description}.",
             "", "**Earth approaches** (the orbit from each published element set; distances centre to centre):", ""]
    lines += approach_rows(tables)
    lines += ["", f"**Spin**: Takahashi et al. 2013 state at its epoch {TOUTATIS_EPOCH.iso[:19]} UTC, planned Scene "
              f"to {END.iso[:10]} under the Sun's and Earth's torques, tolerance 1″: route {result.plan.route}, "
              f"integrator {result.plan.integrator}, error estimate {result.error_estimate.to_value(u.arcsec):.2g}″ "
              f"({'met' if result.tolerance_met else 'NOT met'}). Periods are the osculating P_ψ, P_φ, means over "
              f"±{WINDOW_DAYS:g} d:", "",
              "| | P_ψ (d) | P_φ (d) |", "|---|---:|---:|",
              f"| epoch, torque-free (anchors 5.369 / 7.412 d) | {p_psi0:.4f} | {p_phi0:.4f} |"]
    for label, date, pub_psi, pub_phi in PUBLISHED_PERIODS:
        ours = mean_periods(Time(date, scale="tdb"))
        lines.append(f"| around {date}, vs {label} {pub_psi} / {pub_phi} d | {ours[0]:.4f} ({ours[0] - pub_psi:+.3f}) "
                     f"| {ours[1]:.4f} ({ours[1] - pub_phi:+.3f}) |")
    first = Time(TOUTATIS_APPROACHES[0][0], scale="tdb")
    after = mean_periods(first + 90 * u.day)
    lines.append(f"| epoch → 90 d after the {TOUTATIS_APPROACHES[0][0]} approach | {p_psi0:.4f} → {after[0]:.4f} "
                 f"({after[0] - p_psi0:+.5f}) | {p_phi0:.4f} → {after[1]:.4f} ({after[1] - p_phi0:+.5f}) |")
    for date, _distance, _t, _s in TOUTATIS_APPROACHES[1:]:
        centre = Time(date, scale="tdb")
        before, after = mean_periods(centre - 90 * u.day), mean_periods(centre + 90 * u.day)
        lines.append(f"| 90 d before → after the {date} approach | {before[0]:.4f} → {after[0]:.4f} "
                     f"({after[0] - before[0]:+.5f}) | {before[1]:.4f} → {after[1]:.4f} ({after[1] - before[1]:+.5f}) |")
    markdown = "\n".join(lines)
    print(markdown)
    print(f"\nwall time {time.perf_counter() - clock:.1f} s")
    if not args.no_write:
        for page in ("asteroids.md", "validation.md"):
            print("wrote", write_section("toutatis_validation", markdown, page=page))


if __name__ == "__main__":
    main()
