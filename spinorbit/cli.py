"""The ``spinorbit`` command: argparse front end, one module per subcommand, errors in words.

Subcommands live in :mod:`spinorbit.commands`, one module each, found by name: adding a command is
adding a module there (``spinorbit/commands/moon.py`` gives ``spinorbit moon``). A command module
defines

``NAME``
    The subcommand as typed (``"torque-free"``).
``SUMMARY``
    One line for ``spinorbit --help``.
``DESCRIPTION``, ``EXAMPLES``
    Text for the command's own ``--help``.
``add_arguments(parser)``
    Declares its options on an :class:`argparse.ArgumentParser`.
``run(args)``
    Does the work and returns the exit status (0). It imports what it needs (astropy, numba
    kernels) inside, so that ``--help`` stays fast.

Error policy: a mistake in the user's input ends the run with exit status 2 and one line on stderr
that says what was expected, what arrived and what to do — no traceback. These are
:class:`spinorbit.InputError` (every option and scene-file key is checked by the commands' one
validation layer, ``spinorbit/commands/_inputs.py``, before any work), :class:`CommandError` (its
subclass for checks of the whole command and for output files) and the package's own validation errors (:class:`spinorbit.InvalidBodyError`,
:class:`spinorbit.InvalidStateError`, :class:`spinorbit.SpinorbitError`, astropy's
``UnitTypeError``). Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import os
import pkgutil
import re
import signal
import sys
import threading

from spinorbit.core.errors import InputError

__all__ = ["main", "console_main", "build_parser", "CommandError", "Terminated", "EXIT_USAGE"]

#: Exit status for a run stopped by bad input (argparse's own convention).
EXIT_USAGE = 2
#: Exit status of a run that could not finish for want of the machines running it (its Dask scheduler
#: or every worker lost): not bad input; what finished is kept, and the same command resumes.
EXIT_INCOMPLETE = 3
#: Exit status after Ctrl-C (128 + SIGINT), as shells report it.
EXIT_INTERRUPTED = 130
#: Exit status after SIGTERM (128 + SIGTERM), as shells report it.
EXIT_TERMINATED = 143
#: Exit status when stdout is closed early (128 + SIGPIPE), as shells report it.
EXIT_BROKEN_PIPE = 141


class CommandError(InputError):
    """A problem with the command line's input or its output files, reported as one line and exit status 2.

    The :class:`spinorbit.InputError` of a check that needs the whole command (two options that
    contradict each other, a file that cannot be written); its message is written whole.
    """

    def __init__(self, message):
        Exception.__init__(self, message)
        self.where = self.expected = self.got = self.advice = None

    def __reduce__(self):
        return type(self), (str(self),)


class Terminated(KeyboardInterrupt):
    """SIGTERM during a command, raised as an interrupt so that the command stops as after Ctrl-C.

    A ``KeyboardInterrupt`` subclass: every clean-up that runs for Ctrl-C (an ensemble stopping its
    workers, keeping its finished chunks) runs for SIGTERM too, and ``except Exception`` does not
    swallow it.
    """


def _raise_terminated(signum, frame):
    raise Terminated


@contextlib.contextmanager
def _sigterm_raises():
    """SIGTERM raises :class:`Terminated` in the main thread for the length of the block (else the
    process would die at once, leaving its worker processes and unfinished files)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


# What argparse must read as a negative number, not an option. Its own pattern (Python < 3.13) misses
# exponents, so ``--omega 1e-4 0 -3e-4`` would fail with "expected 3 arguments".
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line with a pointer to ``--help`` (not usage + error)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}. Run '{self.prog} --help' for usage.\n")


def _command_modules():
    """The subcommand modules in :mod:`spinorbit.commands`, in name order (private ``_*`` skipped)."""
    from spinorbit import commands

    names = sorted(info.name for info in pkgutil.iter_modules(commands.__path__) if not info.name.startswith("_"))
    return [importlib.import_module(f"{commands.__name__}.{name}") for name in names]


def build_parser() -> argparse.ArgumentParser:
    """The ``spinorbit`` parser with one subparser per command module."""
    from spinorbit import __version__

    parser = _Parser(
        prog="spinorbit",
        description="Rotation of rigid bodies (tumbling asteroids, librating moons) with Fukushima's "
        "canonical elements. Each command below has its own help: spinorbit COMMAND --help.",
        epilog="example:\n  spinorbit torque-free --moments 3.0836 3.235 1 --omega 14.51 33.529 -98.709\n\n"
        "Documentation: in a source checkout, sphinx-build docs docs/_build/html builds it (offline);\n"
        "docs/cli.md explains every option and the output table.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"spinorbit {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND", dest="command", required=True)
    for module in _command_modules():
        sub = subparsers.add_parser(
            module.NAME,
            help=module.SUMMARY,
            description=module.DESCRIPTION,
            epilog=module.EXAMPLES,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        module.add_arguments(sub)
        sub.set_defaults(_run=module.run, _prog=sub.prog)
    return parser


def _input_errors():
    """Exception types that mean "the input was wrong", imported lazily (they pull in astropy)."""
    from astropy.units import UnitTypeError

    from spinorbit import InvalidBodyError, InvalidStateError, SpinorbitError

    return (CommandError, InvalidBodyError, InvalidStateError, SpinorbitError, UnitTypeError)


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split()) or type(error).__name__


def console_main() -> int:
    """The ``spinorbit`` console script and ``python -m spinorbit``: :func:`main` in a process of its own.

    The process ends right after the command, and the interpreter's last garbage collection at exit
    walks every object numba and astropy made, a large part of a warm ``spinorbit moon``'s wall time
    (``benchmarks/bench_startup.py --before REV`` times the command against an older revision).
    Freezing them (:func:`gc.freeze`) skips that walk; the OS frees the memory. Atexit handlers and
    the destructors of objects without reference cycles still run. In-process callers (tests,
    notebooks) use :func:`main`, which leaves the collector alone.
    """
    status = main()
    gc.freeze()
    return status


def main(argv=None) -> int:
    """Run the ``spinorbit`` command line; return the exit status.

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; ``sys.argv[1:]`` if not given.

    Returns
    -------
    int
        0 on success, 1 when an ensemble member failed, 2 for bad input or an output that cannot be
        written, 3 when an ensemble's scheduler or workers were lost, 130 after Ctrl-C (SIGINT), 143
        after SIGTERM, 141 if stdout was closed early.
    """
    args = build_parser().parse_args(argv)
    from spinorbit.commands._compile_notice import compile_notice

    try:
        with _sigterm_raises(), compile_notice():
            return args._run(args)
    except BrokenPipeError:
        # stdout was closed early (`spinorbit ... | head`): stop quietly, as Unix tools do on SIGPIPE.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt as interrupt:
        how = "terminated (SIGTERM)" if isinstance(interrupt, Terminated) else "interrupted"
        kept = f" {interrupt}" if str(interrupt) else ""  # what a command kept (an ensemble's finished chunks)
        print(f"{args._prog}: {how}; no output was written for the unfinished run.{kept}", file=sys.stderr)
        return EXIT_TERMINATED if isinstance(interrupt, Terminated) else EXIT_INTERRUPTED
    except Exception as error:
        if not isinstance(error, _input_errors()):
            raise
        print(f"{args._prog}: error: {_one_line(error)}", file=sys.stderr)
        return EXIT_USAGE
