"""What bad input gets: runs one representative case of each kind per class of issue 14 and writes
the tables of docs/stability.md ("What bad input gets") from what the package actually raised.

Every row is produced by running the call: the exception type and the start of its message, or the
exit status and line of the command. The caps in the prose come from the constants in the code.
``tests/stress/test_bad_input_table.py`` checks that the page holds what this script writes now.

    PYTHONPATH=. python benchmarks/bad_input.py            # rewrite the section
    PYTHONPATH=. python benchmarks/bad_input.py --no-write # print it
"""

from __future__ import annotations

import contextlib
import io
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
from astropy import units as u

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from _report import write_section  # noqa: E402

from spinorbit import RigidBody, RotationState, cli, special  # noqa: E402
from spinorbit.core.dynamics.equations import make_model  # noqa: E402
from spinorbit.core.dynamics.validation import MAX_OUTPUT_ROWS  # noqa: E402
from spinorbit.core.integrators.dop853 import DEFAULT_MAX_STEPS  # noqa: E402
from spinorbit.core.integrators.quaternion import STEPS_PER_TURN_COEFFICIENT, integrate_fixed_step, integrate_quaternion  # noqa: E402,E501
from spinorbit.core.integrators.splitting import integrate_splitting  # noqa: E402
from spinorbit.core.model.perturbers import kepler_source  # noqa: E402
from spinorbit.runs.checkpoint import Checkpoint  # noqa: E402
from spinorbit.special import MAX_REDUCED_ARGUMENT  # noqa: E402
from spinorbit.state import ANDOYER_G_RANGE, MAX_FLOW_PHASE  # noqa: E402

SECTION = "bad_input"
BODY = RigidBody([1.0, 2.0, 2.5])
Q = [1.0, 0.0, 0.0, 0.0]
STATE = np.array([1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.3])
MESSAGE_CHARS = 110
GOOD = Checkpoint("test", {"y": np.arange(4.0)}, {"k": 1}).to_bytes()


def _flip(data: bytes, position: int) -> bytes:
    return data[:position] + bytes([data[position] ^ 1]) + data[position + 1:]


def _resign(edit) -> bytes:
    import hashlib
    import json

    from spinorbit.runs.checkpoint import MAGIC, TRAILER_BYTES

    end = GOOD.index(b"\n", len(MAGIC))
    header = json.loads(GOOD[len(MAGIC):end])
    edit(header)
    body = MAGIC + json.dumps(header, sort_keys=True).encode() + b"\n" + GOOD[end + 1:-TRAILER_BYTES]
    return body + b"sha256 " + hashlib.sha256(body).hexdigest().encode() + b"\n"


def _cli(*argv, files=None):
    """The command's exit status and stderr line; ``files`` (name → bytes) are written to {dir} first."""
    def run():
        err = io.StringIO()
        with tempfile.TemporaryDirectory() as directory, contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(err):
            for name, data in (files or {}).items():
                Path(directory, name).write_bytes(data)
            try:
                status = cli.main([a.replace("{dir}", directory) for a in argv])
            except SystemExit as exit_info:
                status = exit_info.code
            line = err.getvalue().strip().replace(directory, "DIR")
        return f"exit {status}", line
    return run


CLASSES = {
    "1. Checkpoint integrity": [
        ("one bit flipped in the header", lambda: Checkpoint.from_bytes(_flip(GOOD, 40))),
        ("one bit flipped in the payload", lambda: Checkpoint.from_bytes(_flip(GOOD, len(GOOD) - 80))),
        ("one bit flipped in the checksum line", lambda: Checkpoint.from_bytes(_flip(GOOD, len(GOOD) - 3))),
        ("cut short", lambda: Checkpoint.from_bytes(GOOD[:-20])),
        ("header edited and re-signed: big-endian dtype", lambda: Checkpoint.from_bytes(
            _resign(lambda h: h["arrays"][0].__setitem__(1, ">f8")))),
        ("header edited and re-signed: byte count", lambda: Checkpoint.from_bytes(
            _resign(lambda h: h["arrays"][0].__setitem__(3, 64)))),
        ("a PNG given as checkpoint", lambda: Checkpoint.from_bytes(b"\x89PNG\r\n\x1a\n")),
        ("`spinorbit moon --resume` of a PNG", _cli("moon", "--model", "rigid", "--resume", "{dir}/run.ckpt",
                                                    files={"run.ckpt": b"\x89PNG\r\n\x1a\n"})),
        ("`spinorbit moon --resume` of a checkpoint with a flipped bit",
         _cli("moon", "--model", "rigid", "--resume", "{dir}/run.ckpt", files={"run.ckpt": _flip(GOOD, 60)})),
    ],
    "2. Units": [
        ("spin as bare floats (no unit)", lambda: RotationState(BODY, Q, [2.18e-4, 0, 0])),
        ("spin 1 Hz", lambda: RotationState(BODY, Q, [1.0, 0, 0] * u.Hz)),
        ("spin 1/day", lambda: RotationState(BODY, Q, [1.0, 0, 0] / u.day)),
        ("spin 1 cycle/day (accepted: 2π rad/day)",
         lambda: f"{RotationState(BODY, Q, [1.0, 0, 0] * u.cycle / u.day).angular_velocity[0]:.6f}"),
        ("spin in m/s", lambda: RotationState(BODY, Q, [1.0, 0, 0] * u.m / u.s)),
        ("dt in Hz", lambda: RotationState(BODY, Q, [1.0, 0, 0] * u.rad / u.day).propagate_torque_free([1.0] * u.Hz)),
        ("mass in metres", lambda: RigidBody([1.0, 2.0, 2.5], mass=1 * u.m)),
        ("`--omega-unit Hz`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0",
                                   "--omega-unit", "Hz")),
        ("`--span 1 2 d`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0", "--span", "1",
                                "2", "d")),
    ],
    "3. Outputs": [
        ("`--output x.txt`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0", "--output",
                                  "{dir}/x.txt")),
        ("`--plot x.jpg`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0", "--plot",
                                "{dir}/x.jpg")),
        ("`--output` and `--checkpoint` on one file", _cli("moon", "--output", "{dir}/a.ecsv", "--checkpoint",
                                                     "{dir}/a.ecsv")),
        ("`--output /dev/null`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0",
                                      "--output", "/dev/null")),
        ("`--output` a directory", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0",
                                        "--output", "{dir}")),
        ("Checkpoint.write to /dev/full", lambda: Checkpoint("x").write("/dev/full")),
    ],
    "4. Degenerate states": [
        ("zero spin: `mode`, `periods`, `energy_ratio`, elements …", lambda: RotationState(BODY, Q, [0, 0, 0] * u.rad / u.day).energy_ratio),
        ("spin 1e-200 rad/day (|I ω| below 1e-150)", lambda: RotationState(BODY, Q, [1e-200, 0, 0] * u.rad / u.day).periods),
        ("spin 1e308 rad/day (I ω overflows)", lambda: RotationState(BODY, Q, [0, 0, 1e308] * u.rad / u.day)),
        ("mass 0 kg", lambda: RigidBody([1.0, 2.0, 2.5], mass=0 * u.kg)),
        ("radius NaN km", lambda: RigidBody([1.0, 2.0, 2.5], radius=math.nan * u.km)),
        ("moment NaN", lambda: RigidBody([1.0, math.nan, 2.5])),
        ("dt with NaN", lambda: RotationState(BODY, Q, [1, 2, 3] * u.rad / u.day).propagate_torque_free([0.0, math.nan] * u.day)),
        ("t_out with inf", lambda: integrate_quaternion(STATE, 0.0, [1.0, math.inf], make_model((1.0, 2.0, 2.5)))),
        ("splitting step NaN", lambda: integrate_splitting(STATE, 0.0, [1.0], make_model((1.0, 2.0, 2.5)), math.nan)),
        ("fixed-step t1 NaN", lambda: integrate_fixed_step(STATE, 0.0, math.nan, 10, make_model((1.0, 2.0, 2.5)))),
        ("perturber G·M NaN", lambda: kepler_source(math.nan, 4.0, 0.3, 0.4, 0.1, 0.2, 0.0)),
    ],
    "5. Bounded work": [
        ("DOP853 over 1e9 days at rtol 1e-12",
         lambda: integrate_quaternion(STATE, 0.0, [1e9], make_model((1.0, 2.0, 2.5)), rtol=1e-12)),
        ("splitting, 1e12 steps", lambda: integrate_splitting(STATE, 0.0, [1e10], make_model((1.0, 2.0, 2.5)), 0.01)),
        ("fixed-step DOP853, n_steps 1e9 > max_steps 1e6",
         lambda: integrate_fixed_step(STATE, 0.0, 1.0, 10**9, make_model((1.0, 2.0, 2.5)), max_steps=10**6)),
        ("`spinorbit moon --span 50 yr --step 0.01 d`", _cli("moon", "--span", "50", "yr", "--step", "0.01", "d")),
        ("`spinorbit torque-free --step 1e-9 d`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1",
                                                       "0", "0", "--step", "1e-9", "d")),
    ],
    "6. Special functions and the free flow at their limits": [
        ("`ellipj(1e9, 0.5)`", lambda: special.ellipj(1e9, 0.5)),
        ("`ellipj(1e-141, 1e300)` (√m·u = 1e9)", lambda: special.ellipj(1e-141, 1e300)),
        ("`pn(1e300, -1, 0.5)`", lambda: special.pn(1e300, -1.0, 0.5)),
        ("`ellippi(-3, φ, 1e220)` inside the domain (accepted)",
         lambda: f"{special.ellippi(-3.0, 0.5 * math.asin(1e-110), 1e220):.15e}"),
        ("free flow, dt = 1e300 d", lambda: RotationState(BODY, Q, [1, 2, 3] * u.rad / u.day).propagate_torque_free([1e300] * u.day)),
    ],
    "7. Command-line input": [
        ("`--span nan d`", _cli("torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "0", "0", "--span", "nan",
                                "d")),
        ("`--moments 1 two 2.5`", _cli("torque-free", "--moments", "1", "two", "2.5", "--omega", "1", "0", "0")),
        ("`--moments 1 1e-400 2`", _cli("torque-free", "--moments", "1", "1e-400", "2", "--omega", "1", "0", "0")),
        ("`--tolerance -1 arcsec`", _cli("toutatis", "--tolerance", "-1", "arcsec", "--plan")),
        ("`--perturbers vulcan`", _cli("toutatis", "--span", "1", "d", "--perturbers", "vulcan", "--plan")),
        ("`--checkpoint-every inf`", _cli("moon", "--checkpoint-every", "inf")),
        ("`--n-times 1e3`", _cli("toutatis", "--n-times", "1e3")),
    ],
}


def outcome(call) -> tuple[str, str]:
    """(what it gets, the start of the message) from running ``call``."""
    try:
        result = call()
    except Exception as error:  # the table reports whatever arrives, including a bug
        text = " ".join(str(error).split())
        return f"`{type(error).__name__}`", text
    if isinstance(result, tuple) and result and isinstance(result[0], str) and result[0].startswith("exit"):
        return result
    return "accepted", str(result)


def _cell(text: str) -> str:
    text = text if len(text) <= MESSAGE_CHARS else text[:MESSAGE_CHARS - 1] + "…"
    return text.replace("|", "\\|").replace("\n", " ")


def markdown() -> str:
    lines = ["## What bad input gets (`benchmarks/bad_input.py`)", "",
             "Each row ran as shown; the message is cut at "
             f"{MESSAGE_CHARS} characters. Caps: |I ω| within [{ANDOYER_G_RANGE[0]:g}, {ANDOYER_G_RANGE[1]:g}]; "
             f"free-flow phase ≤ {MAX_FLOW_PHASE:g} rad; elliptic arguments ≤ {MAX_REDUCED_ARGUMENT:.4g} "
             f"(2²⁸π); output rows ≤ {MAX_OUTPUT_ROWS:g} per call; max_steps {DEFAULT_MAX_STEPS:g} by default, "
             f"DOP853's estimate {STEPS_PER_TURN_COEFFICIENT:g}·rtol^(−1/8) steps per rotation.", ""]
    for title, cases in CLASSES.items():
        lines += [f"### {title}", "", "| input | gets | message |", "|---|---|---|"]
        for label, call in cases:
            kind, message = outcome(call)
            lines.append(f"| {_cell(label)} | {kind} | {_cell(message)} |")
        lines.append("")
    return "\n".join(lines)


def main(argv=None) -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/stability.md")
    args = parser.parse_args(argv)
    text = markdown()
    print(text)
    if not args.no_write:
        print(f"wrote {write_section(SECTION, text, page='stability.md')}")


if __name__ == "__main__":
    main()
