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


def number(text: str) -> float:
    """An argparse ``type``: a finite float that float64 holds as typed (no overflow to inf, no underflow to 0)."""
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got '{text}'") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got '{text}'")
    mantissa = text.strip().lower().split("e")[0]
    if value == 0.0 and any(digit in mantissa for digit in "123456789"):
        raise argparse.ArgumentTypeError(f"expected a number float64 can hold, got '{text}', which underflows to 0")
    return value


def quantity(option: str, words, default_unit: str, physical_type: str, example: str):
    """Read ``--span 100 d`` / ``--span "100 d"`` / ``--span 100`` (default unit) as a Quantity.

    The checks are :func:`spinorbit.quantities.parse_quantity`'s, the API's own: one finite number
    and a unit of ``physical_type`` (that of ``default_unit``). Raises
    :class:`~spinorbit.cli.CommandError` naming the option, the expected kind of quantity and what
    arrived.
    """
    from spinorbit.quantities import QuantityInputError, parse_quantity

    try:
        return parse_quantity(option, words, default_unit, example)
    except QuantityInputError as error:
        raise CommandError(str(error)) from None


def unit(option: str, text: str, physical_type: str, example: str):
    """An astropy unit of the given physical type, or a :class:`~spinorbit.cli.CommandError`.

    ``physical_type`` is "angular velocity", "time" or "angle"; a frequency given for an angular
    velocity gets the advice of :mod:`spinorbit.quantities` (write ``cycle/d``).
    """
    from spinorbit.quantities import QuantityInputError, parse_unit

    reference = {"angular velocity": "rad/d", "time": "d", "angle": "rad"}[physical_type]
    try:
        return parse_unit(option, text, reference, example)
    except QuantityInputError as error:
        raise CommandError(str(error)) from None


#: What ``--output`` writes, by the file's extension (astropy's format names); anything else is refused.
TABLE_FORMATS = {".ecsv": "ascii.ecsv", ".csv": "ascii.csv"}
#: What ``--plot`` writes, by the file's extension (matplotlib's format names); anything else is refused.
PLOT_FORMATS = {".png": "png", ".pdf": "pdf", ".svg": "svg"}
#: The options that name files a command writes, and the formats each accepts (None: any name).
OUTPUT_OPTIONS = {"--output": TABLE_FORMATS, "--plot": PLOT_FORMATS, "--checkpoint": None}


def _format_of(option: str, path: str, formats: dict) -> str:
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in formats:
        raise CommandError(
            f"{option} writes {' or '.join(sorted(formats))} files, chosen by the extension; got '{path}'. "
            f"Name the file e.g. {os.path.splitext(path)[0] or 'out'}{next(iter(formats))}."
        )
    return formats[suffix]


def table_format(path: str) -> str:
    """astropy's format for an ``--output`` file: ECSV for .ecsv, CSV for .csv (else CommandError)."""
    return _format_of("--output", path, TABLE_FORMATS)


def plot_format(path: str) -> str:
    """matplotlib's format for a ``--plot`` file: png, pdf or svg from the extension (else CommandError)."""
    return _format_of("--plot", path, PLOT_FORMATS)


def check_output_path(option: str, path: str, formats: dict | None = None) -> None:
    """Fail before a long run, not after it, if ``path`` cannot be written or would destroy something.

    Refused: a directory, a symbolic link (the atomic rename would replace the link, not the file it
    points to: give the target's own path), an existing file that is not a regular file (a device
    such as /dev/null, a pipe, a socket), a missing or unwritable directory, and (with ``formats``)
    an extension the option does not write.
    """
    from spinorbit.runs.atomic import refuse_unsafe_target

    try:
        refuse_unsafe_target(path)
    except OSError as error:
        raise CommandError(f"{option}: will not write '{path}': {error.strerror}.") from None
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise CommandError(
            f"{option}: cannot write '{path}': the directory '{directory}' does not exist; create it first or "
            "choose another path."
        )
    if not os.access(directory, os.W_OK):
        raise CommandError(f"{option}: cannot write '{path}': the directory '{directory}' is not writable; choose "
                           "another path.")
    if formats is not None:
        _format_of(option, path, formats)


def check_output_paths(args) -> None:
    """Every file option of ``args`` (--output, --plot, --checkpoint) can be written, and no two are one file.

    ``--resume`` counts too: no output may overwrite the checkpoint a run resumes from (except
    ``--checkpoint``, which continues it).
    """
    given = [(option, getattr(args, option[2:], None)) for option in OUTPUT_OPTIONS]
    given = [(option, path) for option, path in given if path is not None]
    for option, path in given:
        check_output_path(option, path, OUTPUT_OPTIONS[option])
    resume = getattr(args, "resume", None)
    named = given + ([("--resume", resume)] if resume is not None else [])
    seen = {}
    for option, path in named:
        key = os.path.realpath(path)
        if key in seen and {seen[key], option} != {"--checkpoint", "--resume"}:
            raise CommandError(f"{seen[key]} and {option} name the same file '{path}'; one would overwrite the "
                               "other. Give each its own path.")
        seen.setdefault(key, option)


def check_outputs(args) -> None:
    """Before a run: the output files can be written (:func:`check_output_paths`), and ``--plot`` has matplotlib."""
    check_output_paths(args)
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


def write_table_output(path: str, table, detail: str) -> None:
    """``--output``: ``table`` as ECSV or CSV by the extension, written atomically; print the 'wrote' line."""
    with atomic_output("--output", path) as temporary:
        table.write(temporary, format=table_format(temporary), overwrite=True)
    print(f"wrote              {path} ({detail})")


def write_plot_output(path: str, draw) -> None:
    """``--plot``: ``draw(temporary_path)`` saves the figure, moved into place atomically; print the 'wrote' line."""
    with atomic_output("--plot", path) as temporary:
        draw(temporary)
    print(f"wrote              {path}")


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
    counted : bool, optional
        Also show "done/total" items (an ensemble's members).
    """

    def __init__(self, total: int, label: str, stream=None, delay: float | None = None, counted: bool = False):
        self.total, self.label = max(int(total), 1), label
        self.stream = sys.stderr if stream is None else stream
        self.enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.start = time.monotonic()
        self.last_draw = 0.0
        self.drawn = False
        self.done = 0
        self.delay = PROGRESS_DELAY_S if delay is None else float(delay)
        self.counted = counted

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
        count = f" {self.done}/{self.total}" if self.counted else ""
        self.stream.write(f"\r{self.label} [{bar}] {100 * fraction:3.0f}%{count} ({elapsed:.0f} s{eta}) ")
        self.stream.flush()
        self.last_draw, self.drawn = now, True

    def close(self) -> None:
        """Finish the bar's line (only if one was drawn)."""
        if self.drawn:
            self._draw(time.monotonic())
            self.stream.write("\n")
            self.stream.flush()
