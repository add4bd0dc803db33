"""One-line errors from the command line for every bad input (issue 14, class 7).

hypothesis picks a command, one of its options and a bad value for that option (text where a number
goes, several values where one goes, NaN/inf, units of the wrong kind, unknown names, paths that
cannot be written or read), and fills the other options with a short valid run. Every such run must
end with exit status 2 and exactly one line on stderr that starts ``spinorbit <command>: error:``,
names the option, shows what arrived and says what is expected or what to do — never a traceback or
a raw numpy/numba/astropy message.
"""

import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.stress._cli import run_cli


EXAMPLES = 120
NUMBER_BAD = ["abc", "nan", "inf", "-inf", "1e400", "[1,2]", "1,2", "", "∞", "0x10", "one"]
QUANTITY_BAD = ["abc", "nan d", "inf d", "1 2 d", "[1,2] d", "1 kg", "1 Hz", "-inf", "1e400 d", "d", "1 d d",
                "nan", "1,5 d"]
COUNT_BAD = ["abc", "1.5", "nan", "1e3", "-5", "0", "1", "10000000000", ""]
#: Words that show the message says what is expected or what to do.
GUIDANCE = ("expect", "give", "use ", "choose", "run '", "create", "start", "resume", "install", "write ", "add ",
            "shorten",
            "name the file")
#: Text that would mean a raw library message reached the user unexplained.
RAW = ("Traceback", "could not convert", "invalid literal", "UnitConversionError", "numba", "TypingError",
       "object has no attribute", "NoneType")

TORQUE_FREE = ["torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "2", "3", "--span", "2", "d",
               "--n-times", "3"]
MOON = ["moon", "--model", "core-corrected", "--span", "2", "d"]
TOUTATIS = ["toutatis", "--span", "1", "d", "--plan"]
APOPHIS = ["apophis", "--span", "1", "d", "--plan"]

#: (command base, option, values the option gets, the bad values) — every value below is wrong.
CASES = [
    (TORQUE_FREE, "--moments", 3, NUMBER_BAD + ["0", "-1", "1e-400"]),
    (TORQUE_FREE, "--omega", 3, NUMBER_BAD),
    (TORQUE_FREE, "--euler313", 3, NUMBER_BAD),
    (TORQUE_FREE, "--omega-unit", 1, ["Hz", "1/d", "km", "abc", "", "[1]", "deg", "d", "kHz"]),
    (TORQUE_FREE, "--span", 1, QUANTITY_BAD + ["0", "0 d"]),
    (TORQUE_FREE[:-2], "--step", 1, QUANTITY_BAD + ["0", "-1 d", "1e-300 d"]),
    (TORQUE_FREE[:-2], "--n-times", 1, COUNT_BAD),
    (TORQUE_FREE, "--output", 1, ["x.txt", "x.fits", "{dir}", "/dev/null", "{dir}/missing/x.ecsv", "{link}"]),
    (TORQUE_FREE, "--plot", 1, ["x.jpg", "x", "{dir}", "/dev/null", "{dir}/missing/x.png"]),
    (MOON, "--span", 1, QUANTITY_BAD + ["0", "-1 yr", "300 yr"]),  # 300 yr: past DE421 from J2000
    (MOON, "--step", 1, QUANTITY_BAD + ["0", "-1 d", "3 d", "1e-9 d"]),
    (MOON, "--model", 1, ["jelly", "", "RIGID"]),
    (MOON, "--checkpoint-every", 1, NUMBER_BAD + ["0", "-1"]),
    (MOON, "--resume", 1, ["{dir}/none.ckpt", "{garbage}", "{dir}"]),
    (MOON, "--checkpoint", 1, ["{dir}", "/dev/null", "{dir}/missing/x.ckpt"]),
    (MOON, "--output", 1, ["x.txt", "{dir}", "/dev/null"]),
    (TOUTATIS, "--span", 1, QUANTITY_BAD + ["0", "-1 d", "30 yr", "1e-300 d"]),
    (TOUTATIS, "--n-times", 1, COUNT_BAD),
    (TOUTATIS, "--tolerance", 1, QUANTITY_BAD + ["0", "-1 arcsec", "1e300 rad", "1 m"]),
    (TOUTATIS, "--perturbers", 1, ["vulcan", "[1]", "", "nan", "sun,earth"]),
    (TOUTATIS, "--output", 1, ["x.txt", "{dir}", "/dev/null"]),
    (APOPHIS, "--span", 1, QUANTITY_BAD + ["0", "-1 d", "3 yr"]),
    (APOPHIS, "--orbit", 1, ["jelly", "", "PUBLISHED"]),
    (APOPHIS, "--tolerance", 1, ["nan arcsec", "1 kg", "0", "1 rad"]),
    (APOPHIS, "--plot", 1, ["x.gif", "{dir}", "/dev/null"]),
]


def in_days(text):
    """A time as a message may show it after converting to days (repr and %g), else nothing."""
    from astropy import units as u

    try:
        days = float(u.Quantity(text if text.strip()[-1].isalpha() else f"{text} d").to_value(u.day))
    except (TypeError, ValueError, IndexError, u.UnitsError):
        return set()
    return {repr(float(days)), f"{days:g}"}


def check_one_line_error(base, option, values, directory, culprit):
    substitute = {"{dir}": str(directory), "{garbage}": str(directory / "garbage.ckpt"),
                  "{link}": str(directory / "link.ecsv")}
    (directory / "garbage.ckpt").write_bytes(b"\x00\x01 not a checkpoint")
    if not (directory / "link.ecsv").is_symlink():
        (directory / "link.ecsv").symlink_to(directory / "target.ecsv")
    values = [substitute.get(v, v).replace("{dir}", str(directory)) for v in values]
    culprit = substitute.get(culprit, culprit).replace("{dir}", str(directory))
    words = [w for v in values for w in (v.split(" ") if option in ("--span", "--step", "--tolerance") else [v])]
    argv = [*base, option, *words]
    before = sorted(p.name for p in directory.iterdir())
    status, err = run_cli(argv)
    lines = err.strip().splitlines()
    assert status == 2, (argv, status, err)
    assert len(lines) == 1, (argv, err)
    line = lines[0]
    assert line.startswith(f"spinorbit {base[0]}: error: "), line
    assert not any(raw in line for raw in RAW), line
    shown = option if option != "--step" or "--span" not in line else "--span/--step"
    assert shown.split("/")[0] in line or option.lstrip("-") in line, (argv, line)
    # what arrived: the bad value as typed (argparse shows a float as typed, a path may be shown as its directory)
    shown_values = {culprit, culprit.replace(" ", ""), os.path.dirname(culprit), *in_days(culprit)} - {""}
    assert not culprit.strip() or any(v in line for v in shown_values) or "expected 3 arguments" in line, (argv, line)
    assert any(g in line.lower() for g in GUIDANCE), (argv, line)
    assert sorted(p.name for p in directory.iterdir()) == before  # nothing written, nothing left behind


@settings(max_examples=EXAMPLES)
@given(st.sampled_from(CASES).flatmap(
    lambda case: st.tuples(st.just(case), st.lists(st.sampled_from(case[3]), min_size=case[2], max_size=case[2]),
                           st.integers(0, case[2] - 1))))
def test_every_bad_option_value_is_one_line_exit_2(drawn):
    (base, option, count, bad), values, position = drawn
    culprit = values[position]
    if count == 3:  # one value bad, the others good, so the message must name the culprit
        values = [culprit if i == position else ("1.5" if option != "--omega" else "1") for i in range(3)]
    with tempfile.TemporaryDirectory() as name:
        check_one_line_error(base, option, values, Path(name), culprit)


@pytest.mark.parametrize("base, option, count, bad", CASES, ids=[f"{c[0][0]} {c[1]}" for c in CASES])
def test_each_bad_value_of_each_option_once(tmp_path, base, option, count, bad):
    for value in bad:
        values = [value] + ["1.5"] * (count - 1) if option != "--omega" else [value, "1", "2"]
        check_one_line_error(base, option, values, tmp_path, value)


def test_unknown_body_in_a_coupled_checkpoint_is_one_line(tmp_path):
    """A checkpoint that names a body the simulation does not have: the lookup fails in words."""
    checkpoint = tmp_path / "run.ckpt"
    base = ["moon", "--model", "core-corrected", "--step", "1", "d", "--span", "3", "d"]
    assert run_cli([*base, "--checkpoint", str(checkpoint), "--checkpoint-every", "1e-9"])[0] == 0
    from spinorbit.runs.checkpoint import Checkpoint


    saved = Checkpoint.read(checkpoint)
    saved.meta["body"]["body"] = "Vulcan"
    saved.write(checkpoint)
    status, err = run_cli([*base, "--resume", str(checkpoint)])
    assert status == 2 and len(err.strip().splitlines()) == 1 and "Vulcan" in err, err
    assert not any(raw in err for raw in RAW)
    assert os.path.exists(checkpoint)
