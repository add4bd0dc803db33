"""``spinorbit apophis``: (99942) Apophis's spin through the 2029 Earth encounter, as a planned Scene."""

from __future__ import annotations

import argparse

from spinorbit.commands._common import check_outputs
from spinorbit.commands._ensemble_command import add_ensemble_arguments, check_ensemble_arguments, run_apophis_ensemble
from spinorbit.commands._scene_command import (
    add_scene_arguments,
    run_and_report,
    span_and_times,
)

NAME = "apophis"
SUMMARY = "Apophis's tumbling spin through the 2029-04-13 Earth encounter (planned scene)"
DESCRIPTION = """\
Propagate the spin of (99942) Apophis (Pravec et al. 2014: short-axis mode, P_psi = 263 h,
P_phi = 27.38 h, moments 0.61 : 0.965 : 1) through its 2029-04-13 close approach to Earth
(38 000 km), under the degree-2 torques of the Sun, Earth and Moon. The orbit is the JPL#218
Horizons state of 2021 integrated in REBOUND with the DE421 planets (default), or the documented
fallback encounter geometry (--orbit geometry).

The run is a spinorbit Scene: a planner decides, within --tolerance, which perturbers can be
dropped (with the bound that justifies it), whether the free motion alone would do, and which
integrator; --plan prints those decisions and their reasons and stops. The span is centred on
the encounter. The published state belongs to 2029-04-08 21:47 TDB (5 d before perigee) whatever
the span: the run goes from there forwards (and backwards for spans over 10 d), so every span
gives the same state at the same time. The rotation phase at 2029 is not published: --phase
(a fraction of P_psi, default 0 = the state as constructed) chooses it, and the summary says which
phase ran. Prints the plan in brief, the periods before and after and the error estimate."""
EXAMPLES = """\
examples:
  spinorbit apophis                                  # +-2 d around the encounter
  spinorbit apophis --plan --perturbers sun earth moon jupiter venus
  spinorbit apophis --span 10 d --output apophis.ecsv --plot apophis.png
  spinorbit apophis --phase 0.25                     # the state moved by P_psi/4 along its free motion
  spinorbit apophis --members 200 --workers 2 --plot apophis_ensemble.png   # the distribution over phase x moments
  spinorbit apophis --members 5000 --scheduler tcp://10.0.0.1:8786 --checkpoint-dir runs/apophis

exit status: 0 on success; 2 with a one-line message if the input is wrong or an output file
cannot be written (nothing is left half-written)."""

#: The published orbit starts in 2021; a year either side of the encounter is what it is meant for.
MAX_SPAN_DAYS = 730.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit apophis``."""
    add_scene_arguments(parser, "4 d", ("sun", "earth", "moon"))
    parser.add_argument("--orbit", choices=("published", "geometry"), default="published",
                        help="JPL#218 Horizons state integrated from 2021 (default) or the fallback encounter geometry")
    parser.add_argument("--phase", type=float, default=0.0, metavar="FRACTION",
                        help="rotation phase at the state's epoch (2029-04-08 21:47 TDB) as a fraction of P_psi "
                        "in [0, 1): unknown from the published solution; default 0, the state as constructed")
    add_ensemble_arguments(parser)


def run(args) -> int:
    """Run ``spinorbit apophis``; return the exit status."""
    import astropy.units as u

    from spinorbit.cli import CommandError
    from spinorbit.data.asteroids import (
        APOPHIS_2029,
        APOPHIS_STATE_EPOCH,
        apophis_encounter_simulation,
        apophis_rotation_state,
    )
    from spinorbit.scene import Orbit

    check_outputs(args)
    check_ensemble_arguments(args)
    if not 0.0 <= args.phase < 1.0:
        raise CommandError(f"--phase expects a fraction of P_psi in [0, 1); got {args.phase:g}.")
    days = span_and_times(args, APOPHIS_2029.time_tdb, MAX_SPAN_DAYS)[0].to_value(u.day)
    if args.members is not None:
        from spinorbit.commands._scene_command import tolerance

        args.tolerance_quantity = tolerance(args)
        return run_apophis_ensemble(args, days)
    start = APOPHIS_2029.time_tdb - 0.5 * days * u.day
    span, times = span_and_times(args, start, MAX_SPAN_DAYS)
    orbit = Orbit.rebound(apophis_encounter_simulation(args.orbit), "Apophis")
    print(f"phase              {args.phase:g} of P_psi at {APOPHIS_STATE_EPOCH.iso[:16]} TDB (the state's epoch; "
          "the published solution leaves the phase unknown: --phase)")
    return run_and_report(args, apophis_rotation_state(args.phase), APOPHIS_STATE_EPOCH, times, orbit, NAME,
                          f"(99942) Apophis through the 2029 encounter, {span.value:g} {span.unit}, "
                          f"phase {args.phase:g}", "h")
