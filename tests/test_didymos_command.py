"""``spinorbit didymos``: the report in words, the table it writes, and its refusals."""

import re

import pytest
from _offline import no_network  # noqa: F401
from astropy.table import QTable

from spinorbit import cli


def run_didymos(capsys, *args):
    status = cli.main(["didymos", *args])
    out, err = capsys.readouterr()
    return status, out, err


def test_report_and_table_with_an_impact(capsys, tmp_path):
    # 30 orbits at order 2: enough to separate the free (~13.8 h) and forced (~11.7 h) lines (resolution
    # 2π/T ≈ 0.3 % of n with the Hann window's main lobe of 2 bins), in about a second once compiled.
    path = tmp_path / "d.ecsv"
    status, out, err = run_didymos(capsys, "--orbits", "30", "--order", "2", "--impact", "--output", str(path))
    assert status == 0, err
    periods = [float(p) for p in re.findall(r"mutual orbit period\s+([\d.]+) h", out)]
    assert len(periods) == 2 and periods[1] < periods[0] - 0.25  # the impact shortens the orbit by ~30 min
    free = [float(p) for p in re.findall(r"free libration\s+period ([\d.]+) ± 0\.5\d h", out)]
    assert all(13.0 < p < 14.5 for p in free), out  # n √(3(B−A)/C) ≈ 13.6 h with its corrections (docs/binary.md)
    assert "dv = 2.5729 mm/s" in out  # β m v / M = 3.61 · 579.4 kg · 6144.9 m/s / 4.9955e9 kg
    table = QTable.read(path)
    assert len(table) == 30 * 40 + 1
    assert {"libration", "impact_libration", "S", "impact_mode"} <= set(table.colnames)
    assert table["libration"].unit == "deg"


@pytest.mark.parametrize("args, message", [
    (["--order", "5"], "--order expects a whole number in [0, 4]"),
    (["--per-orbit", "4"], "--per-orbit expects at least 8"),
    (["--orbits", "100000"], "more than 1000000"),
])
def test_bad_options_are_refused_in_words(capsys, args, message):
    status, _, err = run_didymos(capsys, *args)
    assert status == 2
    assert message in err
