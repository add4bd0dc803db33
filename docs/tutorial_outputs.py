"""Regenerate the printed output in docs/tutorials.md from a fresh run of each snippet.

Every ```python block of the page that is followed by a line "prints" and a ```text block is run
(from the checkout, in a fresh namespace, stdout captured) and the text block is replaced by what it
printed, so the numbers on the page are the code's and cannot go stale. ``tests/test_docs.py`` runs
the cheap snippets (:data:`CHEAP`) and checks the committed text equals a fresh run.

Usage::

    python docs/tutorial_outputs.py            # rewrite docs/tutorials.md (all snippets, a minute or so)
    python docs/tutorial_outputs.py --check    # exit 1 and show the difference if any output is stale
    python docs/tutorial_outputs.py --only 0 1 # just these snippets (0-based, in page order)
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import io
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "tutorials.md"
#: A snippet and the output block that follows it ("prints" on its own line in between).
SNIPPET = re.compile(r"```python\n(?P<code>.*?)```\n\nprints\n\n```text\n(?P<output>.*?)```", re.S)
#: Snippets fast enough for the default tests (the torque-free tutorial: no orbits, no integration).
CHEAP = (0, 1)


def snippets(text):
    """The (code, committed output, match) of each snippet with an output block, in page order."""
    return [(m["code"], m["output"], m) for m in SNIPPET.finditer(text)]


def run_snippet(code):
    """What ``code`` prints, run from the checkout in a fresh namespace."""
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
        fresh = run_snippet(code)
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
    text = PAGE.read_text(encoding="utf-8")
    new, changes = regenerate(text, set(args.only) if args.only else None)
    stale = [(i, old, fresh) for i, old, fresh in changes if old != fresh]
    for index, old, fresh in stale:
        print(f"snippet {index}: output changed")
        sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), fresh.splitlines(True), "committed", "fresh"))
    if args.check:
        return 1 if stale else 0
    PAGE.write_text(new, encoding="utf-8")
    print(f"rewrote {PAGE.relative_to(ROOT)}: {len(changes)} snippets run, {len(stale)} outputs changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
