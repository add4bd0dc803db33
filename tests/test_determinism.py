"""Results are deterministic (issue 7): the same run gives the same bits twice in one process and
in a fresh process (torque-free flow, each core integrator, the coupled Moon over 20 days).

Compared through SHA-256 digests of the output arrays (``tests/_determinism_runs.py``), i.e. ``==``
on every bit. Numba is configured without fastmath and with cache=True: a fresh process loads the
same machine code, and nothing in the runs depends on threads, clocks or unseeded randomness.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import _determinism_runs as runs
import pytest

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def first_digests():
    return runs.digests()


def test_same_run_twice_in_one_process_gives_the_same_bits(first_digests):
    assert runs.digests() == first_digests
    assert len(set(first_digests.values())) == len(runs.RUNS)  # the runs differ from each other


def test_a_fresh_process_gives_the_same_bits(first_digests):
    env = dict(os.environ, PYTHONHASHSEED="12345")  # a different hash seed must not matter either
    output = subprocess.run([sys.executable, str(HERE / "_determinism_runs.py")], env=env, check=True,
                            capture_output=True, text=True).stdout
    assert json.loads(output) == first_digests
