"""The fluid core's angular velocity at a start date, carried once from DE421's epoch and then reused.

DE421 publishes the lunar core's spin only at its epoch JDEPOC (1969-06-28).
:func:`spinorbit.coupling.moon.core_angular_velocity` carries it from there to a run's start date with
DE421's own lunar model, and that costs seconds: DE421's orbits over three decades are sampled and
integrated. The answer depends only on the inputs, so it is computed once:

- **J2000** (the default start): shipped with the package in
  :mod:`spinorbit.coupling.lunar_core_j2000`. That module is written by
  ``python -m spinorbit.coupling.ship_lunar_core`` and holds the inputs' key and the provenance next to
  the numbers. ``tests/test_lunar_core.py`` recomputes the value and compares it with the shipped one.
- **any other date**: cached on disk, one JSON file per key, in ``$SPINORBIT_CACHE_DIR`` (default
  ``$XDG_CACHE_HOME/spinorbit`` or ``~/.cache/spinorbit``). Each file carries a SHA-256 checksum of
  its content. A file that fails the check, or whose key differs, is recomputed and rewritten. A
  cache that cannot be written only costs the recomputation next time.

The key is every input of the carry: the start day, the whole DE421 header (the constants and
initial conditions), the model's tolerances and perturbers, and :data:`CORE_MODEL_REVISION`. That
revision number is raised when the lunar equations change, so a stale value is never reused.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

__all__ = ["CORE_MODEL_REVISION", "cache_directory", "cached_core_state", "core_key", "key_digest"]

#: Raised whenever the lunar model's equations or its carrying change (the shipped value and every
#: cached one then stop matching). ``tests/test_lunar_core.py`` recomputes the shipped value to catch
#: a change made without raising it.
CORE_MODEL_REVISION = 1


def key_digest(key: dict) -> str:
    """SHA-256 (hex) of ``key`` written as canonical JSON (sorted keys; floats as Python writes them)."""
    return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()


def core_key(day: float, **settings) -> dict:
    """The key of the core's state at ``day``: the day, the model ``settings`` (tolerances, perturbers …),
    :data:`CORE_MODEL_REVISION` and the SHA-256 of the whole DE421 header (constants and initial conditions)."""
    from spinorbit.ephemeris import de421_constants

    header = de421_constants().header
    return {"day": float(day), "revision": CORE_MODEL_REVISION, **settings,
            "de421_header_sha256": key_digest({name: header[name] for name in sorted(header)})}


def cache_directory() -> Path:
    """Where the carried core states are cached: ``$SPINORBIT_CACHE_DIR``, else the XDG cache dir."""
    explicit = os.environ.get("SPINORBIT_CACHE_DIR")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "spinorbit"


def _shipped(digest: str):
    from spinorbit.coupling import lunar_core_j2000

    return tuple(lunar_core_j2000.CORE_OMEGA) if lunar_core_j2000.KEY_SHA256 == digest else None


def _record(key: dict, value) -> dict:
    body = {"key": key, "core_omega": list(value)}
    return {**body, "sha256": key_digest(body)}


def _read(path: Path, key: dict):
    try:
        record = json.loads(path.read_text())
        body = {"key": record["key"], "core_omega": record["core_omega"]}
        if record["sha256"] != key_digest(body) or record["key"] != key:
            return None
        value = tuple(float(x) for x in record["core_omega"])
    except (OSError, ValueError, KeyError, TypeError):  # absent, unreadable, truncated or altered
        return None
    return value if len(value) == 3 else None


def _write(path: Path, key: dict, value) -> None:
    from spinorbit.runs.atomic import write_bytes_atomically

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bytes_atomically(path, json.dumps(_record(key, value), indent=1).encode())
    except OSError:
        pass  # a read-only or full cache costs the recomputation next time, never the run


def cached_core_state(key: dict, compute):
    """The core's angular velocity for ``key``: shipped, cached on disk, or ``compute()`` (then cached).

    Parameters
    ----------
    key : dict
        Every input of the computation (JSON-serialisable; see the module docstring).
    compute : callable
        Returns the value (three floats, rad/day on DE421's mantle axes) when neither the shipped
        value nor the cache has it.

    Returns
    -------
    tuple of float
    """
    digest = key_digest(key)
    shipped = _shipped(digest)
    if shipped is not None:
        return shipped
    path = cache_directory() / f"lunar_core_{digest}.json"
    value = _read(path, key)
    if value is None:
        value = tuple(float(x) for x in compute())
        _write(path, key, value)
    return value
