"""Helpers shared by the subcommands: quantities from the command line, atomic output, progress."""

from __future__ import annotations

import contextlib
import os
import sys
import time

from spinorbit.cli import CommandError

#: Seconds a run must take before the progress bar shows itself.
PROGRESS_DELAY_S = 2.0
#: Seconds between redraws of the progress bar.
PROGRESS_REDRAW_S = 0.2


def quantity(option: str, words, default_unit: str, physical_type: str, example: str):
    """Read ``--span 100 d`` / ``--span "100 d"`` / ``--span 100`` (default unit) as a Quantity.

    Raises :class:`~spinorbit.cli.CommandError` naming the option, the expected kind of quantity and
    what arrived.
    """
    import astropy.units as u

    text = " ".join(words) if isinstance(words, (list, tuple)) else str(words)
    try:
        value = u.Quantity(text)
    except (TypeError, ValueError):
        value = None
    if value is not None and value.unit == u.dimensionless_unscaled:
        value = value.value * u.Unit(default_unit)
    if value is None or value.isscalar is False or value.unit.physical_type != physical_type:
        raise CommandError(
            f"{option} expects a {physical_type} such as '{example}' (a number alone means {default_unit}); "
            f"got '{text}'."
        )
    return value


def unit(option: str, text: str, physical_type: str, example: str):
    """An astropy unit of the given physical type, or a :class:`~spinorbit.cli.CommandError`."""
    import astropy.units as u

    try:
        result = u.Unit(text)
    except (TypeError, ValueError):
        result = None
    if result is None or result.physical_type != physical_type:
        raise CommandError(f"{option} expects a unit of {physical_type} such as {example}; got '{text}'.")
    return result


def check_output_path(option: str, path: str) -> None:
    """Fail before a long run, not after it, if ``path`` cannot be written."""
    directory = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise CommandError(f"{option} expects a file name; '{path}' is a directory. Give a file path, e.g. {path}/out.")
    if not os.path.isdir(directory):
        raise CommandError(
            f"{option}: the directory '{directory}' does not exist; create it first or choose another path."
        )
    if not os.access(directory, os.W_OK):
        raise CommandError(f"{option}: the directory '{directory}' is not writable; choose another path.")


def check_outputs(args) -> None:
    """Before a run: ``--output`` and ``--plot`` (when given) can be written, and ``--plot`` has matplotlib."""
    for option, path in (("--output", args.output), ("--plot", args.plot)):
        if path is not None:
            check_output_path(option, path)
    if args.plot is not None:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise CommandError("--plot needs matplotlib; install it with: pip install 'spinorbit[plot]'") from None


@contextlib.contextmanager
def atomic_output(option: str, path: str):
    """Yield a temporary path next to ``path``; on success move it into place, on failure delete it.

    :func:`spinorbit.runs.atomic.atomic_path` with the command line's error wording: readers never see a
    half-written file, a failed run leaves nothing behind, and an ``OSError`` becomes a
    :class:`~spinorbit.cli.CommandError` that names the option and the path.
    """
    from spinorbit.runs.atomic import atomic_path

    try:
        with atomic_path(path) as temporary:
            yield temporary
    except OSError as error:
        raise CommandError(f"{option}: cannot write '{path}' ({error.strerror}); choose another path.") from None


class Progress:
    """A dependency-free progress bar on stderr for runs longer than :data:`PROGRESS_DELAY_S`.

    Silent when stderr is not a terminal (pipes, CI logs, tests) and for short runs.

    Parameters
    ----------
    total : int
        Number of work items.
    label : str
        Word shown before the bar.
    stream : file, optional
        Where to draw (stderr by default).
    delay : float, optional
        Seconds before the bar shows itself (:data:`PROGRESS_DELAY_S` by default).
    """

    def __init__(self, total: int, label: str, stream=None, delay: float | None = None):
        self.total, self.label = max(int(total), 1), label
        self.stream = sys.stderr if stream is None else stream
        self.enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.start = time.monotonic()
        self.last_draw = 0.0
        self.drawn = False
        self.done = 0
        self.delay = PROGRESS_DELAY_S if delay is None else float(delay)

    def advance(self, count: int) -> None:
        """Record ``count`` more items done; redraw if due."""
        self.done += count
        self.tick()

    def tick(self) -> None:
        """Redraw if due (the elapsed time moves on even while no item is done)."""
        now = time.monotonic()
        if self.enabled and now - self.start >= self.delay and now - self.last_draw >= PROGRESS_REDRAW_S:
            self._draw(now)

    def _draw(self, now: float) -> None:
        fraction = min(self.done / self.total, 1.0)
        filled = int(30 * fraction)
        elapsed = now - self.start
        eta = f", {elapsed * (1 - fraction) / fraction:.0f} s left" if 0 < fraction < 1 else ""
        bar = "#" * filled + "." * (30 - filled)
        self.stream.write(f"\r{self.label} [{bar}] {100 * fraction:3.0f}% ({elapsed:.0f} s{eta}) ")
        self.stream.flush()
        self.last_draw, self.drawn = now, True

    def close(self) -> None:
        """Finish the bar's line (only if one was drawn)."""
        if self.drawn:
            self._draw(time.monotonic())
            self.stream.write("\n")
            self.stream.flush()
