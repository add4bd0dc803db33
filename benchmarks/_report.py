"""Write a benchmark's results into its own marked section of a Markdown page in ``docs/``.

Each benchmark owns the text between ``<!-- BEGIN name -->`` and ``<!-- END name -->``; the rest of
the page (prose written by hand) is left untouched. The page is written atomically.
"""

from __future__ import annotations

import os
import platform
from datetime import datetime, timezone
from pathlib import Path

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
    """The command line of a benchmark timed best of ``--repeat``: measure, print its Markdown and, unless
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
