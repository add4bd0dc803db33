"""Write a benchmark's results into its own marked section of a Markdown page in ``docs/``.

Each benchmark owns the text between ``<!-- BEGIN name -->`` and ``<!-- END name -->``; the rest of
the page (prose written by hand) is left untouched. The page is written atomically.
"""

from __future__ import annotations

import math
import os
import platform
import time
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from spinorbit.runs.atomic import write_bytes_atomically

DOCS = Path(__file__).resolve().parent.parent / "docs"


def machine_line() -> str:
    """One line naming the machine and the versions a benchmark ran with."""
    import numpy

    try:
        import numba

        numba_version = numba.__version__
    except ImportError:  # pragma: no cover
        numba_version = "absent"
    return (
        f"Measured {datetime.now(timezone.utc):%Y-%m-%d} on {platform.machine()} "
        f"({os.cpu_count()} cores), Python {platform.python_version()}, numpy {numpy.__version__}, "
        f"numba {numba_version}."
    )


@dataclass(frozen=True)
class Timing:
    """Repeated timings of one run (s): the median to compare, the minimum and the spread beside it.

    On a shared machine a single best-of hides how the load moved the runs; the median and the
    min–max range of interleaved repeats show both the typical cost and the noise.
    """

    samples: tuple

    @property
    def min(self) -> float:
        return min(self.samples)

    @property
    def max(self) -> float:
        return max(self.samples)

    @property
    def median(self) -> float:
        return float(np.median(self.samples))

    @property
    def iqr(self) -> tuple:
        """(first quartile, third quartile) (s)."""
        q1, q3 = np.percentile(self.samples, [25, 75])
        return float(q1), float(q3)

    def text(self, scale: float = 1e3, fmt: str = ".2f") -> str:
        """'median (min–max, n runs)' in units of 1/scale s (ms by default)."""
        return (f"{self.median * scale:{fmt}} ({self.min * scale:{fmt}}–{self.max * scale:{fmt}}, "
                f"{len(self.samples)} runs)")


def interleaved_timings(functions, repeats: int, clock=time.perf_counter, budget_s: float = math.inf,
                        warm_up: bool = False):
    """Time ``functions`` alternately (f0, f1, …, f0, f1, …) so that all see the same machine load.

    Parameters
    ----------
    functions : sequence of callables
    repeats : int
        Rounds (each calls every function once); fewer if ``budget_s`` of clock time is spent first.
    clock : callable
        ``time.perf_counter`` (wall) or ``time.process_time`` (CPU of this process).
    budget_s : float
        Stop after the round in which the summed time of all calls exceeds this (s).
    warm_up : bool
        Call each function once, untimed, first (compilation, caches).

    Returns
    -------
    timings : list of Timing
        One per function.
    results : list
        Each function's result from its last call.
    """
    functions = list(functions)
    results = [f() if warm_up else None for f in functions]
    samples = [[] for _ in functions]
    spent = 0.0
    for _ in range(max(1, repeats)):
        for i, f in enumerate(functions):
            start = clock()
            results[i] = f()
            elapsed = clock() - start
            samples[i].append(elapsed)
            spent += elapsed
        if spent > budget_s:
            break
    return [Timing(tuple(s)) for s in samples], results


def write_section(name: str, markdown: str, page: str = "performance.md") -> Path:
    """Replace (or append) the section ``name`` of ``docs/<page>`` with ``markdown``."""
    path = DOCS / page
    begin, end = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    block = f"{begin}\n{markdown.rstrip()}\n{end}\n"
    text = path.read_text() if path.exists() else f"# {page.removesuffix('.md').title()}\n\n"
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        text = head + block + tail.lstrip("\n")
    else:
        text = text.rstrip("\n") + "\n\n" + block
    path.parent.mkdir(parents=True, exist_ok=True)
    write_bytes_atomically(path, text.encode())
    return path


def repeat_main(section: str, description: str, measure, markdown, repeat: int = 3, argv=None) -> None:
    """The command line of a benchmark timed ``--repeat`` times: measure, print its Markdown and, unless
    ``--no-write``, write it as ``section`` of docs/performance.md."""
    import argparse

    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--repeat", type=int, default=repeat)
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    args = parser.parse_args(argv)
    text = markdown(measure(args.repeat), args.repeat)
    print(text)
    if not args.no_write:
        print(f"wrote {write_section(section, text)}")


#: Prefix of the line a benchmark prints for each goal it holds a ratio to (``benchmarks/run_all.py``
#: collects these lines from every script's output and prints them together, each with its bar).
RATIO_PREFIX = "ratio: "


def ratio_goal(name: str, ratio: float, bar: float, at_most: bool = False, stretch: float | None = None) -> str:
    """A performance goal as a ratio to a peer or a floor measured in the same run: prints its line for
    run_all (``RATIO_PREFIX``) and returns the verdict for the Markdown, e.g. ``"1.32× (bar ≥ 1×): met"``.

    Why ratios: absolute rates on the shared 2-core machines move by 1.5× from run to run, a ratio of
    two engines timed interleaved in one process much less. ``at_most``: the bar is an upper bound (a
    time over a floor's); ``stretch``: a second, optional bar on the same side.
    """
    sign = "≤" if at_most else "≥"
    met = ratio <= bar if at_most else ratio >= bar
    if met:
        verdict = "met"
    else:
        short = ratio / bar if at_most else bar / ratio
        verdict = f"missed by a factor {short:.2f}"
    text = f"{ratio:.3g}× (bar {sign} {bar:g}×): {verdict}"
    if stretch is not None:
        stretch_met = ratio <= stretch if at_most else ratio >= stretch
        text += f"; stretch {sign} {stretch:g}×: {'met' if stretch_met else 'not met'}"
    print(f"{RATIO_PREFIX}{name} = {text}", flush=True)
    return text
