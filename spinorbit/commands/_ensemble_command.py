"""``spinorbit apophis --members N``: the post-encounter spin state as a distribution, its summary and histograms."""

from __future__ import annotations

import contextlib
import logging
import sys

from spinorbit.cli import EXIT_INCOMPLETE, CommandError
from spinorbit.commands import _inputs as check
from spinorbit.commands._common import Progress, plot_format, write_plot_output, write_table_output

#: Most members the command accepts in one call (a larger study belongs in a script with a checkpoint).
MAX_MEMBERS = 1_000_000


def add_ensemble_arguments(parser) -> None:
    """--members, --workers / --scheduler, --seed, --checkpoint-dir."""
    group = parser.add_argument_group("ensemble (the distribution over the unknown phase and the moment ratios)")
    group.add_argument("--members", metavar="N",
                       help="run N members, both rotation phases uniform and the moment ratios uniform between the two "
                       "published solutions; --output writes one row per member, --plot the histograms")
    where = group.add_mutually_exclusive_group()
    where.add_argument("--workers", metavar="K", help="K local worker processes (default: one per core)")
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://10.0.0.1:8786")
    group.add_argument("--seed", default=None, help="root seed of the members' draws (default: the one stored in "
                       "--checkpoint-dir, else fresh entropy; printed at the start and stored there, so the same "
                       "command resumes)")
    group.add_argument("--checkpoint-dir", metavar="DIR", help="keep completed chunks in DIR; run again with the same "
                       "DIR and options to run only the missing members")


def check_ensemble_arguments(args) -> None:
    """--members, --seed, --workers and --scheduler in range, before any work."""
    if args.members is None:
        if args.workers is not None or args.scheduler is not None or args.checkpoint_dir:
            raise CommandError("--workers, --scheduler and --checkpoint-dir go with --members N (an ensemble); add "
                               "--members.")
        return
    args.members = check.integer("--members", args.members, "200", low=1, high=MAX_MEMBERS)
    if args.seed is not None:
        args.seed = check.seed("--seed", args.seed)
    if args.workers is not None:
        args.workers = check.integer("--workers", args.workers, "2", low=1)
    if args.scheduler is not None:
        check.scheduler_address("--scheduler", args.scheduler)


def _executor(args):
    if args.scheduler is not None:
        check.scheduler_address("--scheduler", args.scheduler)
        from spinorbit.ensemble.executors import dask_client

        try:
            return dask_client(args.scheduler)
        except (OSError, TimeoutError) as error:
            raise CommandError(f"--scheduler: cannot reach the Dask scheduler at '{args.scheduler}' ({error}); check "
                               "the address (tcp://host:port) and that the scheduler runs.") from None
    if args.workers is not None:
        if args.workers < 1:
            raise CommandError(f"--workers expects a positive number of worker processes; got {args.workers}.")
        return "serial" if args.workers == 1 else args.workers
    return None


def run_apophis_ensemble(args, span_days) -> int:
    """Run the ensemble, print the summary, write --output (one row per member) and --plot (histograms)."""

    from spinorbit.ensemble import Ensemble, EnsembleInterrupted
    from spinorbit.ensemble.apophis import apophis_member, apophis_parameters

    check_ensemble_arguments(args)
    tolerance = float(args.tolerance_quantity.to_value("arcsec"))
    seed = _seed(args)
    parameters = apophis_parameters(args.members, seed, span_days=span_days, orbit=args.orbit,
                                    perturbers=tuple(args.perturbers), tolerance_arcsec=tolerance)
    ensemble = Ensemble(apophis_member, parameters)
    executor = _executor(args)
    progress = Progress(args.members, "members", counted=True)
    with _quiet_dask_client():  # also while the client closes: its reconnection attempts log tracebacks
        try:
            table = ensemble.run(executor=executor, checkpoint=args.checkpoint_dir,
                                 progress=lambda done, total: progress.advance(done - progress.done))
        except KeyboardInterrupt as interrupt:  # Ctrl-C or SIGTERM: say what is kept (the CLI prints it)
            raise type(interrupt)(_kept(ensemble, args)) from None
        except EnsembleInterrupted as lost:  # the scheduler or the workers went away: not bad input
            progress.close()
            cause = " ".join(f"{type(lost.cause).__name__}: {lost.cause}".split())
            print(f"{args._prog}: stopped: {lost.members_lost} of {ensemble.n_members} members did not come back "
                  f"from {lost.executor} ({cause}). {_kept(ensemble, args)}", file=sys.stderr)
            return EXIT_INCOMPLETE
        finally:
            progress.close()
            if hasattr(executor, "close"):
                executor.close()
    for line in summary(table, ensemble):
        print(line)
    if args.output is not None:
        write_table_output(args.output, table, f"{len(table)} members")
    if args.plot is not None:
        write_plot_output(args.plot, lambda temporary: histograms(table, temporary, plot_format(args.plot)))
    return 0 if not ensemble.failures else 1


@contextlib.contextmanager
def _quiet_dask_client():
    """Dask's client logs a lost scheduler as a traceback of its own reconnection (36 lines) before the
    run's one-line error says the same; its logger is kept to critical messages while the run lasts."""
    # dask's logging config gives its modules' loggers levels of their own, so each is set, not the parent
    loggers = [logging.getLogger(name) for name in ("distributed", "distributed.client", "distributed.core",
                                                      "distributed.comm", "distributed.utils")]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


def _seed(args) -> int:
    """The members' root seed: --seed, else the one stored in --checkpoint-dir (a resume), else fresh
    entropy; printed before the run, so that a killed run can always be repeated or resumed."""
    import numpy as np

    from spinorbit.ensemble.store import stored_seed

    if args.seed is not None:
        print(f"seed               {args.seed} (--seed)")
        return args.seed
    stored = None if args.checkpoint_dir is None else stored_seed(args.checkpoint_dir)
    if stored is not None:
        print(f"seed               {stored} (stored in '{args.checkpoint_dir}': this run resumes the ensemble there)")
        return stored
    seed = int(np.random.SeedSequence().entropy)
    where = (f"stored in '{args.checkpoint_dir}', so the same command resumes" if args.checkpoint_dir is not None
             else "add --checkpoint-dir DIR to keep finished chunks")
    print(f"seed               {seed} (fresh; --seed {seed} draws the same members; {where})", flush=True)
    return seed


def _kept(ensemble, args) -> str:
    """What an interrupted run leaves: the members of its finished chunks, and where."""
    done = ensemble.members_complete
    if args.checkpoint_dir is None:
        return (f"{done} of {ensemble.n_members} members had finished; without --checkpoint-dir they are not "
                "kept (add it to keep finished chunks on disk).")
    return (f"{done} of {ensemble.n_members} members are kept in '{args.checkpoint_dir}'; run the same command "
            "again to run only the rest.")


def _values(table, name):
    import numpy as np

    column = table[name]
    data = np.ma.masked_invalid(np.ma.asarray(getattr(column, "unmasked", column).value if hasattr(column, "unit") and
                                              column.unit is not None else np.asarray(column, dtype=float)))
    mask = getattr(column, "mask", None)
    if mask is not None and np.any(mask):
        data = np.ma.array(data, mask=np.asarray(mask))
    return data.compressed()


def summary(table, ensemble) -> list[str]:
    """Lines: members, spread of the post-encounter periods, E/E0, modes, pole shift; failures; wall time."""
    import numpy as np

    ok = np.array([not e for e in table["error"]])
    n_ok = int(ok.sum())
    lines = [f"ensemble           {len(table)} members (phase uniform on the free motion's torus, moment ratios "
             f"{table['i1_i3'].min():.3f}-{table['i1_i3'].max():.3f} : {table['i2_i3'].min():.4f}-"
             f"{table['i2_i3'].max():.4f} : 1), seed entropy {table.meta.get('seed_entropy', '?')}; "
             f"{ensemble.last_run['executor']}"]
    if n_ok:
        ratio = _values(table, "sidereal_period") / _values(table, "sidereal_period_initial")
        shift = _values(table, "pole_shift")
        modes = [str(m) for m, good in zip(table["mode"], ok) if good]
        fractions = ", ".join(f"{m} {modes.count(m) / n_ok:.0%}" for m in sorted(set(modes)))
        for name, label in (("P_psi", "P_psi"), ("P_phi", "P_phi"), ("energy_ratio", "E/E0")):
            values = _values(table, name)
            initial = _values(table, f"{name}_initial")
            unit = " h" if name != "energy_ratio" else ""
            lines.append(f"{label:18s} after {np.min(values):.4g}-{np.max(values):.4g}{unit} (median {np.median(values):.4g}"
                         f"{unit}); before {np.min(initial):.4g}-{np.max(initial):.4g}{unit}")
        lines.append(f"sidereal period    after/before {np.min(ratio):.3g}-{np.max(ratio):.3g} (median {np.median(ratio):.3g}); "
                     f"halved or less {np.mean(ratio <= 0.5):.0%}, doubled or more {np.mean(ratio >= 2.0):.0%}")
        lines.append(f"pole shift         {np.min(shift):.3g}-{np.max(shift):.3g} deg (median {np.median(shift):.3g}); "
                     f"10 deg or more in {np.mean(shift >= 10.0):.0%} of the members")
        lines.append(f"modes after        {fractions}")
        worst = np.max(_values(table, "error_estimate"))
        lines.append(f"error estimate     at most {worst:.3g} arcsec per member")
    failures = ensemble.failures
    lines.append(f"failures           {len(failures)}" + (f" (first: member {failures[0]['index']}, {failures[0]['type']}: "
                                                          f"{failures[0]['message']})" if failures else ""))
    lines.append(f"wall time          {ensemble.last_run['wall_seconds']:.2f} s ({ensemble.last_run['members_run']} members "
                 f"run, {ensemble.last_run['members_restored']} restored from the checkpoint)")
    return lines


def histograms(table, path, file_format) -> None:
    """P_psi, P_phi, E/E0, sidereal period ratio, pole shift histograms and the mode fractions."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    figure, axes = plt.subplots(2, 3, figsize=(12, 7))
    panels = (("P_psi", "P_psi after (h)"), ("P_phi", "P_phi after (h)"), ("energy_ratio", "E/E0 after"))
    for axis, (name, label) in zip(axes[0], panels):
        axis.hist(_values(table, name), bins="auto", color="tab:blue")
        axis.axvline(np.median(_values(table, f"{name}_initial")), color="k", linestyle="--", label="before (median)")
        axis.set_xlabel(label)
        axis.legend(fontsize="small")
    ratio = _values(table, "sidereal_period") / _values(table, "sidereal_period_initial")
    axes[1][0].hist(ratio, bins="auto", color="tab:green")
    for mark in (0.5, 2.0):
        axes[1][0].axvline(mark, color="k", linestyle=":")
    axes[1][0].set_xlabel("sidereal period after / before (dotted: halved, doubled)")
    axes[1][1].hist(_values(table, "pole_shift"), bins="auto", color="tab:red")
    axes[1][1].axvline(10.0, color="k", linestyle=":")
    axes[1][1].set_xlabel("pole shift (deg; dotted: 10 deg)")
    ok = [str(m) for m, e in zip(table["mode"], table["error"]) if not e]
    names = sorted(set(ok))
    axes[1][2].bar(names, [ok.count(m) / max(len(ok), 1) for m in names], color="tab:purple")
    axes[1][2].set_ylabel("fraction of members")
    axes[1][2].set_title("mode after the encounter")
    for axis in axes.flat[:5]:
        axis.set_ylabel("members")
    figure.suptitle(f"(99942) Apophis after the 2029 encounter: {len(table)} members over phase x moment ratios")
    figure.tight_layout()
    figure.savefig(path, format=file_format)
    plt.close(figure)
