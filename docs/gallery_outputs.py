"""Run the gallery's examples and commit what they print and plot, for the docs build to show.

The documentation build does not run the examples (they integrate orbits for seconds to minutes,
and the default tests build the docs). This script runs each ``examples/*.py`` once, the way a user
would (``python examples/<name>.py <arguments>``, matplotlib's Agg backend, in a temporary directory),
and writes ``docs/gallery/<name>.txt`` (what it printed) and ``docs/gallery/<name>.png`` (the last
figure it left open, or else the newest PNG it wrote). ``docs/conf.py`` appends both to the example's
gallery page. An example chooses its gallery arguments with one comment line in its source::

    # gallery-arguments: --quick --output plot.png

and its gallery thumbnail, the committed plot, with sphinx-gallery's own comment (hidden on the page)::

    # sphinx_gallery_thumbnail_path = "gallery/<name>.png"

Usage::

    python docs/gallery_outputs.py                 # every example (minutes)
    python docs/gallery_outputs.py apophis_2029    # just these
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import runpy
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
OUTPUTS = ROOT / "docs" / "gallery"
ARGUMENTS = re.compile(r"^# gallery-arguments:(.*)$", re.M)


def gallery_arguments(source):
    """The command-line arguments an example asks for in its ``# gallery-arguments:`` line ([] if none)."""
    match = ARGUMENTS.search(source)
    return shlex.split(match[1]) if match else []


def run_example(path):
    """(printed text, path of the plot or None) of one run of the example at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    arguments = gallery_arguments(path.read_text(encoding="utf-8"))
    work = Path(tempfile.mkdtemp(prefix=f"gallery-{path.stem}-"))
    buffer = io.StringIO()
    saved_argv, saved_cwd = sys.argv, os.getcwd()
    sys.argv = [str(path), *arguments]
    os.chdir(work)
    plt.close("all")
    try:
        with contextlib.redirect_stdout(buffer):
            try:
                runpy.run_path(str(path), run_name="__main__")
            except SystemExit as stop:
                if stop.code not in (None, 0):
                    raise
        plot = None
        if plt.get_fignums():
            plot = work / "_gallery_figure.png"
            plt.figure(plt.get_fignums()[-1]).savefig(plot, dpi=100)
        else:
            pngs = sorted(work.glob("*.png"), key=lambda p: p.stat().st_mtime)
            plot = pngs[-1] if pngs else None
        return buffer.getvalue(), plot, work
    finally:
        sys.argv = saved_argv
        os.chdir(saved_cwd)
        plt.close("all")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("names", nargs="*", help="example names (default: all examples/*.py)")
    args = parser.parse_args(argv)
    paths = [EXAMPLES / f"{n}.py" for n in args.names] if args.names else sorted(EXAMPLES.glob("*.py"))
    OUTPUTS.mkdir(exist_ok=True)
    sys.path.insert(0, str(ROOT))
    for path in paths:
        clock = time.perf_counter()
        text, plot, work = run_example(path)
        (OUTPUTS / f"{path.stem}.txt").write_text(text, encoding="utf-8")
        if plot is not None:
            shutil.copyfile(plot, OUTPUTS / f"{path.stem}.png")
        shutil.rmtree(work, ignore_errors=True)
        print(f"{path.name}: {len(text.splitlines())} lines{', a plot' if plot else ''} "
              f"({time.perf_counter() - clock:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
