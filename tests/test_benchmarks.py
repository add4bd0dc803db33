"""benchmarks/run_all.py: every benchmark is registered, and its quick (smoke) mode runs without writing docs/.

The full smoke run (every script, ≈ 10 min on 2 cores) is slow; the default suite checks the registry
and runs one cheap script through run_all the way the full run does.
"""

import hashlib
import importlib
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BENCHMARKS = ROOT / "benchmarks"


def _run_all():
    return importlib.import_module("benchmarks.run_all")


def _docs_digest():
    """SHA-256 of every file under docs/ (a quick run must leave them all as they were)."""
    digest = hashlib.sha256()
    for path in sorted((ROOT / "docs").rglob("*")):
        if path.is_file():
            digest.update(str(path.relative_to(ROOT)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def test_every_benchmark_script_is_registered_once():
    run_all = _run_all()
    registered = [b.script for b in run_all.BENCHMARKS]
    assert len(registered) == len(set(registered))
    scripts = {path.name for path in BENCHMARKS.glob("*.py")}
    missing = scripts - set(registered) - set(run_all.LIBRARY_MODULES)
    assert not missing, f"add {sorted(missing)} to run_all.BENCHMARKS (or LIBRARY_MODULES if it measures nothing)"
    assert set(registered) <= scripts
    assert not set(registered) & set(run_all.LIBRARY_MODULES)


def test_quick_arguments_never_write_docs():
    """Each quick argument list asks its script for the print-only mode (--quick or --no-write)."""
    for benchmark in _run_all().BENCHMARKS:
        assert {"--quick", "--no-write"} & set(benchmark.quick), benchmark.script


def test_unknown_script_is_refused_by_name():
    with pytest.raises(SystemExit, match="unknown benchmark.*nope.py"):
        _run_all().run(["nope.py"], quick=True)


def test_one_quick_benchmark_through_run_all(capsys):
    before = _docs_digest()
    results = _run_all().run(["accuracy_elliptic.py"], quick=True)
    assert [(script, status) for script, status, _ in results] == [("accuracy_elliptic.py", 0)]
    assert _docs_digest() == before


@pytest.mark.slow
def test_every_benchmark_runs_in_quick_mode():
    before = _docs_digest()
    run_all = _run_all()
    results = run_all.run(quick=True, stream=sys.stdout)
    failed = [(script, status) for script, status, _ in results if status != 0]
    assert not failed, run_all.summary(results)
    assert _docs_digest() == before


def test_ratio_goals_are_printed_for_run_all_and_judged_on_their_side(capsys):
    report = importlib.import_module("benchmarks._report")
    assert _run_all().RATIO_PREFIX == report.RATIO_PREFIX  # run_all keeps its own copy (no package import)
    assert report.ratio_goal("a / peer", 1.32, 1.0, stretch=1.5) == "1.32× (bar ≥ 1×): met; stretch ≥ 1.5×: not met"
    assert report.ratio_goal("b / peer", 0.3, 1.0).endswith("missed by a factor 3.33")
    assert report.ratio_goal("c / floor", 25.0, 30.0, at_most=True) == "25× (bar ≤ 30×): met"
    assert report.ratio_goal("d / floor", 45.0, 30.0, at_most=True).endswith("missed by a factor 1.50")
    printed = [line for line in capsys.readouterr().out.splitlines() if line.startswith(report.RATIO_PREFIX)]
    assert [line.split(" = ")[0] for line in printed] == ["ratio: a / peer", "ratio: b / peer", "ratio: c / floor",
                                                          "ratio: d / floor"]


def test_summary_lists_every_ratio_with_its_bar():
    text = _run_all().summary([("x.py", 0, 1.0)], [("x.py", "a / peer = 1.32× (bar ≥ 1×): met")])
    assert "| x.py | a / peer = 1.32× (bar ≥ 1×): met |" in text
