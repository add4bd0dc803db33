"""Run the asteroid commands shown in docs/cli.md and write their printed output there.

Sections written (``<!-- BEGIN name -->`` … ``<!-- END name -->`` of docs/cli.md): ``cli_apophis``
(``spinorbit apophis`` at four spans, which agree after the encounter since the state belongs to its
epoch), ``cli_toutatis_plan`` (a plan of ``spinorbit toutatis``), ``cli_asteroid`` (``spinorbit asteroid`` with
``examples/asteroid_scene.toml``) and ``cli_didymos`` (``spinorbit didymos --impact``). The
numbers in those sections come from this script only.

Usage::

    PYTHONPATH=$PWD python benchmarks/cli_examples.py            # ≈ 60 s
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT))

from _report import machine_line, write_section  # noqa: E402

from spinorbit import cli  # noqa: E402


def printed(argv):
    """What ``spinorbit argv`` prints on stdout, with the wall-time line (it varies) kept."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = cli.main(argv)
    if status != 0:
        raise SystemExit(f"spinorbit {' '.join(argv)} failed with status {status}")
    return out.getvalue().rstrip()


def main():
    write = "--no-write" not in sys.argv[1:] and "--quick" not in sys.argv[1:]  # --quick: print only
    scene = ROOT / "examples" / "asteroid_scene.toml"
    with tempfile.TemporaryDirectory() as work:
        here = os.getcwd()
        os.chdir(work)  # the scene file's outputs land here, not in the checkout
        try:
            apophis = [(span, printed(["apophis", "--span", span, "d"])) for span in ("4", "4.1", "6", "10")]
            asteroid = printed(["asteroid", "--scene", str(scene)])
            toutatis = printed(["toutatis", "--plan", "--span", "0.01", "d", "--tolerance", "100", "arcsec"])
            didymos = printed(["didymos", "--impact"] + ([] if write else ["--orbits", "10"]))
        finally:
            os.chdir(here)
    blocks = [machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:", ""]
    for span, text in apophis:
        blocks += [f"```text\n$ spinorbit apophis --span {span} d\n{text}\n```", ""]
    print("\n".join(blocks))
    print(asteroid)
    if not write:
        return
    write_section("cli_apophis", "\n".join(blocks), page="cli.md")
    write_section("cli_asteroid", "\n".join([machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:", "",
                                             f"```text\n$ spinorbit asteroid --scene examples/asteroid_scene.toml\n"
                                             f"{asteroid}\n```"]), page="cli.md")
    write_section("cli_toutatis_plan", "\n".join([
        machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:", "",
        f"```text\n$ spinorbit toutatis --plan --span 0.01 d --tolerance 100 arcsec\n{toutatis}\n```"]), page="cli.md")
    write_section("cli_didymos", "\n".join([
        machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:", "",
        f"```text\n$ spinorbit didymos --impact\n{didymos}\n```"]), page="cli.md")


if __name__ == "__main__":
    main()
