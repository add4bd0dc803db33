"""Start-up stays cheap: what a fresh process loads, and the start-up benchmark runs (issue 18)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _loaded_after(statement: str) -> set:
    """Top-level packages in ``sys.modules`` after ``statement`` in a fresh interpreter."""
    code = f"import sys, json\n{statement}\nprint(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}})))"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, check=True, capture_output=True,
                         text=True).stdout
    return set(json.loads(out.strip().splitlines()[-1]))


def test_import_spinorbit_core_loads_neither_numba_nor_astropy():
    loaded = _loaded_after("import spinorbit.core")
    assert not loaded & {"numba", "astropy", "rebound", "scipy"}, loaded & {"numba", "astropy", "rebound", "scipy"}


@pytest.mark.parametrize("module", ["spinorbit.coupling.moon", "spinorbit.commands.moon"])
def test_the_de421_moon_route_does_not_load_rebound(module):
    # The default `spinorbit moon` (the "de421" model) runs on DE421's orbits; REBOUND's import and its
    # compiled extra forces belong to the rigid routes only.
    assert "rebound" not in _loaded_after(f"import {module}")


@pytest.mark.parametrize("module", ["spinorbit.coupling.moon", "spinorbit.commands.moon"])
def test_the_de421_moon_route_does_not_load_astropy_coordinates(module):
    # astropy.coordinates (and astropy.table with it) cost a fifth of a warm `spinorbit moon`; only
    # writing the Moon table (--output) needs them (spinorbit.state_table, imported there).
    code = (f"import sys, json\nimport {module}\n"
            "print(json.dumps(sorted(m for m in sys.modules if m.startswith('astropy.'))))")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, check=True, capture_output=True,
                         text=True).stdout
    loaded = set(json.loads(out.strip().splitlines()[-1]))
    assert not loaded & {"astropy.coordinates", "astropy.table"}, loaded & {"astropy.coordinates", "astropy.table"}


def test_startup_benchmark_writes_its_table(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "benchmarks/bench_startup.py", "--repeat", "1", "--cold-repeat", "0",
                          "--no-write"], cwd=ROOT, env=env, check=True, capture_output=True, text=True).stdout
    for row in ("| import spinorbit.core |", "| spinorbit moon (warm) |", "| DE421 orbit sampling |"):
        assert row in out, out
