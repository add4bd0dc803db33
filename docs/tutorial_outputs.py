"""Regenerate the printed output in docs/tutorials.md and docs/cli.md from a fresh run of each snippet.

Every ```python or ```bash block of those pages that is followed by a paragraph starting "prints" and a
```text block is run and the text block is replaced by what it printed, so the numbers on the pages are
the code's and cannot go stale. Python runs from the checkout in a fresh namespace; each ``spinorbit …``
line of a bash block runs as ``python -m spinorbit …`` in a temporary directory (the files it writes
are thrown away). ``tests/test_docs.py`` runs the cheap tutorial snippets (:data:`CHEAP`) and checks
the committed text equals a fresh run (the command outputs print wall times, so they are regenerated,
not compared).

Usage::

    python docs/tutorial_outputs.py            # rewrite both pages (all snippets, a minute or so)
    python docs/tutorial_outputs.py --check    # exit 1 and show the difference if any output is stale
    python docs/tutorial_outputs.py --only 0 1 # just these snippets of docs/tutorials.md (0-based)
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import io
import os
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "tutorials.md"
#: The pages whose outputs the script regenerates.
PAGES = (PAGE,)  # docs/cli.md: benchmarks/cli_examples.py
#: A snippet and the output block that follows it (a paragraph starting "prints" in between).
SNIPPET = re.compile(r"```(?P<language>python|bash)\n(?P<code>(?:(?!```).)*)```\n\nprints[^\n]*\n(?:[^\n]+\n)*\n"
                     r"```text\n(?P<output>(?:(?!```).)*)```", re.S)
#: Snippets fast enough for the default tests (the torque-free tutorial: no orbits, no integration).
CHEAP = (0, 1)


def snippets(text):
    """The (code, committed output, match) of each snippet with an output block, in page order."""
    return [(m["code"], m["output"], m) for m in SNIPPET.finditer(text)]


def run_commands(code):
    """What the ``spinorbit …`` lines of a bash block print (stdout), run in a temporary directory."""
    lines = code.replace("\\\n", " ").splitlines()
    commands = [shlex.split(line, comments=True) for line in lines if line.strip().startswith("spinorbit ")]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    printed = []
    with tempfile.TemporaryDirectory() as work:
        for words in commands:
            result = subprocess.run([sys.executable, "-m", "spinorbit", *words[1:]], capture_output=True, text=True,
                                    cwd=work, env=env, timeout=600)
            if result.returncode != 0:
                raise RuntimeError(f"{' '.join(words)} failed: {result.stderr}")
            printed.append(result.stdout)
    return "".join(printed)


def run_snippet(code, language="python"):
    """What ``code`` prints: Python from the checkout in a fresh namespace, or a bash block's commands."""
    if language == "bash":
        return run_commands(code)
    sys.path.insert(0, str(ROOT))
    buffer = io.StringIO()
    try:
        with contextlib.redirect_stdout(buffer):
            exec(compile(code, "<tutorial snippet>", "exec"), {"__name__": "__tutorial__"})
    finally:
        sys.path.remove(str(ROOT))
    return buffer.getvalue()


def regenerate(text, only=None):
    """(new page text, [(index, committed, fresh)]) with the chosen snippets' outputs replaced by fresh runs."""
    pieces, last, changes = [], 0, []
    for index, (code, output, match) in enumerate(snippets(text)):
        if only is not None and index not in only:
            continue
        fresh = run_snippet(code, match["language"])
        start, end = match.span("output")
        pieces += [text[last:start], fresh]
        last = end
        changes.append((index, output, fresh))
    pieces.append(text[last:])
    return "".join(pieces), changes


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="compare only; exit 1 if an output is stale")
    parser.add_argument("--only", type=int, nargs="+", help="indices of the snippets to run (0-based)")
    args = parser.parse_args(argv)
    any_stale = False
    for page in PAGES if not args.only else (PAGE,):
        text = page.read_text(encoding="utf-8")
        new, changes = regenerate(text, set(args.only) if args.only else None)
        stale = [(i, old, fresh) for i, old, fresh in changes if old != fresh]
        any_stale = any_stale or bool(stale)
        for index, old, fresh in stale:
            print(f"{page.name} snippet {index}: output changed")
            sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), fresh.splitlines(True), "committed",
                                                       "fresh"))
        if not args.check:
            page.write_text(new, encoding="utf-8")
            print(f"rewrote {page.relative_to(ROOT)}: {len(changes)} snippets run, {len(stale)} outputs changed")
    return 1 if args.check and any_stale else 0


if __name__ == "__main__":
    sys.exit(main())
