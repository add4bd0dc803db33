"""The lunar core's state at a start date is computed once: shipped for J2000, cached on disk elsewhere."""

import json

import numpy as np
import pytest

from spinorbit.coupling import lunar_core, lunar_core_j2000
from spinorbit.coupling.lunar_core import cached_core_state, key_digest
from spinorbit.coupling.moon import _epoch_day, carry_core_angular_velocity, core_angular_velocity, core_state_key

#: Shipped against recomputed ω_c (rad/day): 4e-12 of |ω_c| = 0.23 rad/day. A platform's rounding
#: through 31 years of DOP853 at rtol 1e-12 moves it far less; a changed model or input moves it far
#: more (the model's own accuracy is 0.001″ ≈ 5e-9 rad).
SHIPPED_ATOL = 1e-12


def test_shipped_j2000_core_is_what_the_model_computes():
    assert lunar_core_j2000.KEY == core_state_key(0.0)
    assert lunar_core_j2000.KEY_SHA256 == key_digest(core_state_key(0.0))
    np.testing.assert_allclose(carry_core_angular_velocity(0.0), lunar_core_j2000.CORE_OMEGA, rtol=0,
                               atol=SHIPPED_ATOL)
    assert core_angular_velocity(0.0) == lunar_core_j2000.CORE_OMEGA


def test_a_changed_input_misses_the_shipped_value(tmp_path, monkeypatch):
    monkeypatch.setenv("SPINORBIT_CACHE_DIR", str(tmp_path))
    key = {**core_state_key(0.0), "rtol": 1e-11}
    calls = []
    assert cached_core_state(key, lambda: calls.append(1) or (1.0, 2.0, 3.0)) == (1.0, 2.0, 3.0)
    assert calls == [1]


def test_other_dates_are_carried_once_then_read_from_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SPINORBIT_CACHE_DIR", str(tmp_path))
    day = _epoch_day() + 20.0  # a short carry keeps the test fast
    key = core_state_key(day)
    calls = []

    def compute():
        calls.append(day)
        return carry_core_angular_velocity(day)

    first = cached_core_state(key, compute)
    assert cached_core_state(key, compute) == first and len(calls) == 1
    (path,) = tmp_path.glob("lunar_core_*.json")
    assert path.name == f"lunar_core_{key_digest(key)}.json"
    assert json.loads(path.read_text())["core_omega"] == list(first)


@pytest.mark.parametrize("damage", ["truncated", "altered value", "other key"])
def test_a_damaged_cache_file_is_recomputed_and_rewritten(tmp_path, monkeypatch, damage):
    monkeypatch.setenv("SPINORBIT_CACHE_DIR", str(tmp_path))
    key = {"day": 1234.5, "test": damage}
    cached_core_state(key, lambda: (1.0, 2.0, 3.0))
    (path,) = tmp_path.glob("lunar_core_*.json")
    record = json.loads(path.read_text())
    if damage == "truncated":
        path.write_text(path.read_text()[:20])
    elif damage == "altered value":  # the checksum no longer matches
        record["core_omega"][0] = 9.0
        path.write_text(json.dumps(record))
    else:  # a valid record, but for different inputs (a digest collision or a copied file)
        body = {"key": {"day": 0.0}, "core_omega": [9.0, 9.0, 9.0]}
        path.write_text(json.dumps({**body, "sha256": key_digest(body)}))
    assert cached_core_state(key, lambda: (4.0, 5.0, 6.0)) == (4.0, 5.0, 6.0)
    assert json.loads(path.read_text())["core_omega"] == [4.0, 5.0, 6.0]


def test_an_unwritable_cache_costs_only_the_recomputation(tmp_path, monkeypatch):
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    monkeypatch.setenv("SPINORBIT_CACHE_DIR", str(blocker / "cache"))
    assert cached_core_state({"day": 1.0}, lambda: (1.0, 2.0, 3.0)) == (1.0, 2.0, 3.0)


def test_cache_directory_follows_the_environment(tmp_path, monkeypatch):
    monkeypatch.delenv("SPINORBIT_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert lunar_core.cache_directory() == tmp_path / "spinorbit"
    monkeypatch.setenv("SPINORBIT_CACHE_DIR", str(tmp_path / "own"))
    assert lunar_core.cache_directory() == tmp_path / "own"
