"""Run the asteroid commands shown in docs/cli.md and write their printed output there.

Sections written (``<!-- BEGIN name -->`` … ``<!-- END name -->`` of docs/cli.md): ``cli_apophis``
(``spinorbit apophis`` at four spans, which agree after the encounter since the state belongs to its
epoch), ``cli_toutatis_plan`` (a plan of ``spinorbit toutatis``), ``cli_asteroid`` (``spinorbit asteroid`` with
``examples/asteroid_scene.toml``) and ``cli_didymos`` (``spinorbit didymos --impact``). The
numbers in those sections come from this script only.

Usage::

    PYTHONPATH=$PWD python benchmarks/cli_examples.py            # ≈ 60 s
    PYTHONPATH=$PWD python benchmarks/cli_examples.py --only didymos   # one command's section
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
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only")
    parser.add_argument("--quick", action="store_true", help="print only, with a short didymos run")
    parser.add_argument("--only", choices=("apophis", "asteroid", "toutatis", "didymos"), default=None,
                        help="run and write one command's section only")
    args = parser.parse_args()
    write = not (args.no_write or args.quick)
    wanted = {"apophis", "asteroid", "toutatis", "didymos"} if args.only is None else {args.only}
    scene = ROOT / "examples" / "asteroid_scene.toml"
    with tempfile.TemporaryDirectory() as work:
        here = os.getcwd()
        os.chdir(work)  # the scene file's outputs land here, not in the checkout
        try:
            apophis = ([(span, printed(["apophis", "--span", span, "d"])) for span in ("4", "4.1", "6", "10")]
                       if "apophis" in wanted else [])
            asteroid = printed(["asteroid", "--scene", str(scene)]) if "asteroid" in wanted else None
            toutatis = (printed(["toutatis", "--plan", "--span", "0.01", "d", "--tolerance", "100", "arcsec"])
                        if "toutatis" in wanted else None)
            didymos = (printed(["didymos", "--impact"] + ([] if write else ["--orbits", "10"]))
                       if "didymos" in wanted else None)
        finally:
            os.chdir(here)
    blocks = [machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:", ""]
    for span, text in apophis:
        blocks += [f"```text\n$ spinorbit apophis --span {span} d\n{text}\n```", ""]
    for text in ("\n".join(blocks) if apophis else None, asteroid, toutatis, didymos):
        if text is not None:
            print(text)
    if not write:
        return
    if apophis:
        write_section("cli_apophis", "\n".join(blocks), page="cli.md")
    if asteroid is not None:
        write_section("cli_asteroid", "\n".join([machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:",
                                                 "", f"```text\n$ spinorbit asteroid --scene examples/asteroid_scene.toml\n"
                                                 f"{asteroid}\n```"]), page="cli.md")
    if toutatis is not None:
        write_section("cli_toutatis_plan", "\n".join([
            machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py`:", "",
            f"```text\n$ spinorbit toutatis --plan --span 0.01 d --tolerance 100 arcsec\n{toutatis}\n```"]), page="cli.md")
    if didymos is not None:
        write_section("cli_didymos", "\n".join([
            machine_line(), "`PYTHONPATH=$PWD python benchmarks/cli_examples.py --only didymos`:", "",
            f"```text\n$ spinorbit didymos --impact\n{didymos}\n```"]), page="cli.md")


if __name__ == "__main__":
    main()
