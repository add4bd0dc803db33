"""Runs whose bits must not change between repetitions or processes (tests/test_determinism.py).

``python tests/_determinism_runs.py`` prints the SHA-256 of each run's output as JSON, so a test can
compare a fresh process with itself.
"""

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from spinorbit.runs.checkpoint import fingerprint
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.integrators.elements import integrate_elements
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.integrators.splitting import integrate_splitting
from spinorbit.core.model.perturbers import kepler_source
from spinorbit.core.free_motion.flow import torque_free_states_many

MOMENTS = (2.0 / 3.0, 1.0, 2.0)
Y0 = np.array([0.9, 0.1, -0.3, 0.2, 0.6, 0.05, 0.5])
Y0[:4] /= np.linalg.norm(Y0[:4])
MODEL = make_model(MOMENTS, [kepler_source(0.3, 4.0, 0.3, 0.4, 0.1, 0.2, 0.0)])
TIMES = np.linspace(0.0, 30.0, 61)[1:]


def torque_free():
    times = np.linspace(0.0, 1e4, 50)
    return torque_free_states_many(np.repeat(Y0[None, :4], times.size, 0), np.repeat(Y0[None, 4:], times.size, 0),
                                   MOMENTS, times)


def moon():
    from spinorbit.coupling.moon import compare_with_de421, moon_at_de421

    comparison = compare_with_de421(moon_at_de421(), 20.0, 1.0)
    return comparison.angles_model


RUNS = {
    "torque_free": torque_free,
    "dop853": lambda: integrate_quaternion(Y0, 0.0, TIMES, MODEL, rtol=1e-12),
    "elements": lambda: integrate_elements(Y0, 0.0, TIMES, MODEL, rtol=1e-12),
    "splitting": lambda: integrate_splitting(Y0, 0.0, TIMES, MODEL, 0.02, scheme="saba3"),
    "coupled_moon": moon,
}


def digests():
    """{run name: SHA-256 of its output arrays}."""
    out = {}
    for name, run in RUNS.items():
        result = run()
        out[name] = fingerprint(*(result if isinstance(result, tuple) else (result,)))
    return out


if __name__ == "__main__":
    print(json.dumps(digests()))
