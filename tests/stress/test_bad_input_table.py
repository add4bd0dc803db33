"""docs/stability.md, "What bad input gets", holds what ``benchmarks/bad_input.py`` measures now.

The script runs every row; this test reruns it and compares each row's input and outcome (the
exception or exit status) and the start of its message with the page, so a change of behaviour
without a regenerated page fails here. (The end of a message may name data another module owns,
such as the particles of a simulation, so only its first words are compared.)
"""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bad_input  # noqa: E402

#: Characters of each message compared with the page.
MESSAGE_PREFIX = 48


def rows(text):
    """(input, gets, message start) of every table row of the section."""
    section = text.split(f"<!-- BEGIN {bad_input.SECTION} -->", 1)[-1].split(f"<!-- END {bad_input.SECTION} -->")[0]
    found = []
    for line in section.splitlines():
        cells = re.split(r"(?<!\\)\|", line)[1:-1]
        if len(cells) == 3 and not set(cells[0].strip()) <= set("-") and cells[0].strip() != "input":
            found.append((cells[0].strip(), cells[1].strip(), cells[2].strip()[:MESSAGE_PREFIX]))
    return found


def test_the_page_shows_what_bad_input_gets_now():
    page = rows((ROOT / "docs" / "stability.md").read_text())
    now = rows(f"<!-- BEGIN {bad_input.SECTION} -->\n{bad_input.markdown()}\n<!-- END {bad_input.SECTION} -->")
    assert len(now) == sum(len(cases) for cases in bad_input.CLASSES.values()) >= 40
    assert page == now, "docs/stability.md is stale: run PYTHONPATH=. python benchmarks/bad_input.py"
    assert all(gets != "accepted" or "accepted" in label for label, gets, _ in now)  # refusals stay refusals
