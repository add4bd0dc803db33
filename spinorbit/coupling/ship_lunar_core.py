"""Write the shipped J2000 lunar core state, :mod:`spinorbit.coupling.lunar_core_j2000` (generated data).

Run ``python -m spinorbit.coupling.ship_lunar_core`` after a change to DE421's lunar model (and after
raising :data:`spinorbit.coupling.lunar_core.CORE_MODEL_REVISION`). The module it writes holds the
value, the digest of its inputs and where it came from; :mod:`spinorbit.coupling.lunar_core` explains
how it is used.
"""

from __future__ import annotations

import datetime
import platform
from pathlib import Path

__all__ = ["write_shipped_module"]


def write_shipped_module(path=None) -> Path:
    """Recompute ω_c at J2000.0 (DE421's lunar model carried from JDEPOC) and write it as a module."""
    import numba
    import numpy

    from spinorbit import __version__
    from spinorbit.coupling.lunar_core import key_digest
    from spinorbit.coupling.moon import carry_core_angular_velocity, core_state_key
    from spinorbit.runs.atomic import write_bytes_atomically

    path = Path(__file__).with_name("lunar_core_j2000.py") if path is None else Path(path)
    key = core_state_key(0.0)
    value = tuple(float(x) for x in carry_core_angular_velocity(0.0))
    now = datetime.datetime.now(datetime.timezone.utc)
    text = f'''"""The lunar fluid core's angular velocity at J2000.0 TDB, carried from DE421's epoch (generated data).

Written by ``python -m spinorbit.coupling.ship_lunar_core``; do not edit by hand.
``tests/test_lunar_core.py`` recomputes the value and compares it with this one.

Provenance: :func:`spinorbit.coupling.moon.carry_core_angular_velocity` (DE421's lunar model, mantle
and core from the DE421 header at JDEPOC 1969-06-28, driven by DE421's orbits to J2000.0), computed
with spinorbit {__version__}, numpy {numpy.__version__}, numba {numba.__version__},
Python {platform.python_version()} on {platform.machine()}, {now:%Y-%m-%d}.
"""

#: The inputs (:func:`spinorbit.coupling.moon.core_state_key` at day 0), for the reader.
KEY = {key!r}
#: SHA-256 of :data:`KEY` (:func:`spinorbit.coupling.lunar_core.key_digest`): what a run compares.
KEY_SHA256 = {key_digest(key)!r}
#: ω_c on DE421's mantle axes at J2000.0 (rad/day).
CORE_OMEGA = {value!r}
'''
    write_bytes_atomically(path, text.encode())
    return path


if __name__ == "__main__":
    print(f"wrote {write_shipped_module()}")
