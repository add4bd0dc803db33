"""``spinorbit toutatis``: (4179) Toutatis's tumbling spin from the 1992 radar state, as a planned Scene."""

from __future__ import annotations

import argparse

from spinorbit.commands._common import check_outputs
from spinorbit.commands._scene_command import (
    add_scene_arguments,
    run_and_report,
    span_and_times,
)

NAME = "toutatis"
SUMMARY = "Toutatis's long-axis tumbling from the 1992 radar state under Sun and Earth torques (planned scene)"
DESCRIPTION = """\
Propagate the spin of (4179) Toutatis from Takahashi, Busch & Scheeres (2013) at 1992-11-09
(long-axis mode, P_psi = 5.369 d, P_phi = 7.412 d) under the degree-2 torques of the Sun and
Earth. The orbit is Toutatis's published osculating elements (JPL SBDB, epoch 2008-11-27)
integrated in REBOUND among the DE421 planets with EIH 1PN and Earth J2: it passes Earth on
1992-12-08 (0.024 au), 2004-09-29 (0.0102 au), 2008-11-09 and 2012-12-12 where the published
approaches are (docs/asteroids.md). --orbit geometry is the older documented 2004-flyby geometry,
kept for comparison (it misses the 1992 approach).

The run is a spinorbit Scene: a planner decides, within --tolerance, which perturbers can be
dropped (with the bound that justifies it), whether the free motion alone would do, and which
integrator; --plan prints those decisions and their reasons and stops. The span starts at the
1992 epoch, 1992-11-09; the whole 1992-2012 run through the 2012-12-12 approach is --span 20.1 yr
(a minute or so; 20 yr = 7305 d ends on 2012-11-09). The summary, the ECSV metadata and the plot
give the close approaches to Earth (within 0.2 au) in the span."""
EXAMPLES = """\
examples:
  spinorbit toutatis                                 # 100 d from 1992-11-09
  spinorbit toutatis --plan --span 1 d --tolerance 100 arcsec
  spinorbit toutatis --span 20.1 yr --n-times 2000 --output toutatis.ecsv --plot toutatis.png

exit status: 0 on success; 2 with a one-line message if the input is wrong or an output file
cannot be written (nothing is left half-written)."""

#: 1992-2014 is the span the orbits were checked on (the elements orbit against the published approaches).
MAX_SPAN_DAYS = 22 * 365.25


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit toutatis``."""
    add_scene_arguments(parser, "100 d", ("sun", "earth"))
    parser.add_argument("--orbit", choices=("elements", "geometry"), default="elements",
                        help="published elements of 2008 integrated with the DE421 planets (default) or the "
                        "documented 2004-flyby geometry")


def run(args) -> int:
    """Run ``spinorbit toutatis``; return the exit status."""
    from spinorbit.data.asteroids import TOUTATIS_EPOCH, toutatis_orbit, toutatis_rotation_state

    check_outputs(args)
    start = TOUTATIS_EPOCH.tdb
    span, times = span_and_times(args, start, MAX_SPAN_DAYS)
    orbit = toutatis_orbit(args.orbit)
    print(f"orbit              {orbit.description}")
    return run_and_report(args, toutatis_rotation_state(), start, times, orbit, NAME,
                          f"(4179) Toutatis from 1992-11-09, {span.value:g} {span.unit}", "d")
