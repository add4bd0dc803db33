"""Catalogue of bad inputs across the public API (issue 7): each gets a specific exception whose
message says what was expected and what arrived.

Each case is (label, call, exception type, pattern the message must contain). The pattern is chosen
to show the *arrived* value or the *expected* form, so a vague "invalid input" would fail the test.
``spinorbit moon`` cases are at the end (exit status 2, one line, no file left behind); the
``torque-free`` ones live in tests/test_cli.py.
"""

import datetime
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit import cli
from spinorbit import special
from spinorbit import RigidBody, RotationState
from spinorbit import time as so_time
from spinorbit.body import InvalidBodyError
from spinorbit.runs.checkpoint import Checkpoint, CheckpointError, CheckpointSchedule
from spinorbit import SingularElementsError
from spinorbit.core import (
    andoyer_to_canonical,
    canonical_to_andoyer,
    torque_free_states_many,
)
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.model.gravity_field import make_body
from spinorbit.core.integrators.elements import integrate_elements
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.integrators.splitting import integrate_splitting
from spinorbit.coupling.long_run import integrate_to_outputs
from spinorbit.coupling.moon import moon_figure
from spinorbit.coupling.one_way import propagate_one_way
from spinorbit.coupling.sampling import de421_orbit, sample_from_ephemeris
from spinorbit.coupling.rebound import (
    ForceInstallError,
    MissingBodyError,
    simulation_from_de421,
)
from spinorbit.coupling.rigid_body import CoupledRigidBody, RestoreError
from spinorbit.ephemeris import (
    EphemerisRangeError,
    UnknownBodyError,
    barycentric_state,
    moon_orientation,
)
from spinorbit.runs.resumable import integrate_resumable
from spinorbit.state import InvalidStateError

BODY = RigidBody([1.0, 2.0, 2.5])
IDENTITY = [1.0, 0.0, 0.0, 0.0]
STATE = np.array([1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.3])
J2000 = Time("2000-01-01T12:00:00", scale="tdb")


def model():
    return make_model((1.0, 2.0, 2.5))


CATALOGUE = [
    # --- rigid bodies
    ("moment NaN", lambda: RigidBody([1.0, math.nan, 2.0]), InvalidBodyError, "finite"),
    ("moment inf", lambda: RigidBody([1.0, math.inf, 2.0]), InvalidBodyError, "finite"),
    ("moment zero", lambda: RigidBody([0.0, 1.0, 1.0]), InvalidBodyError, "positive"),
    ("moment negative", lambda: RigidBody([-1.0, 2.0, 2.0]), InvalidBodyError, r"-1\.0"),
    ("two moments", lambda: RigidBody([1.0, 2.0]), InvalidBodyError, r"\(2,\)"),
    ("four moments", lambda: RigidBody([1.0, 2.0, 3.0, 4.0]), InvalidBodyError, r"\(4,\)"),
    ("moments text", lambda: RigidBody("abc"), TypeError, "'abc'"),
    ("triangle inequality", lambda: RigidBody([1.0, 1.0, 3.0]), InvalidBodyError, "A \\+ B ≥ C"),
    ("moments in metres", lambda: RigidBody([1.0, 2.0, 2.5] * u.m), u.UnitTypeError, "kg m"),
    ("mass in metres", lambda: RigidBody([1.0, 2.0, 2.5], mass=3 * u.m), u.UnitTypeError, "mass unit"),
    ("radius in kg", lambda: RigidBody([1.0, 2.0, 2.5], radius=3 * u.kg), u.UnitTypeError, "length unit"),
    # --- rotation states
    ("quaternion of 3", lambda: RotationState(BODY, [1.0, 0.0, 0.0], [1, 0, 0] * u.rad / u.day), InvalidStateError, r"\(3,\)"),
    ("zero quaternion", lambda: RotationState(BODY, [0.0] * 4, [1, 0, 0] * u.rad / u.day), InvalidStateError, "= 0.0"),
    ("non-unit quaternion", lambda: RotationState(BODY, [2.0, 0, 0, 0], [1, 0, 0] * u.rad / u.day), InvalidStateError, "= 2.0"),
    ("NaN quaternion", lambda: RotationState(BODY, [math.nan, 0, 0, 1], [1, 0, 0] * u.rad / u.day), InvalidStateError, "nan"),
    ("NaN spin", lambda: RotationState(BODY, IDENTITY, [1.0, math.nan, 0] * u.rad / u.day), InvalidStateError, "nan"),
    ("spin of 2", lambda: RotationState(BODY, IDENTITY, [1.0, 0.0] * u.rad / u.day), InvalidStateError, r"\(2,\)"),
    ("spin in m/s", lambda: RotationState(BODY, IDENTITY, [1.0, 0, 0] * u.m / u.s), u.UnitTypeError, "m / s"),
    ("body not a RigidBody", lambda: RotationState([1, 2, 3], IDENTITY, [1, 0, 0] * u.rad / u.day), TypeError, "list"),
    ("reflection matrix", lambda: RotationState.from_matrix(BODY, np.diag([1.0, 1, -1]), [1, 0, 0] * u.rad / u.day), InvalidStateError, "det"),
    ("sheared matrix", lambda: RotationState.from_matrix(BODY, [[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], [1, 0, 0] * u.rad / u.day), InvalidStateError, "not a rotation"),
    ("matrix 2x2", lambda: RotationState.from_matrix(BODY, np.eye(2), [1, 0, 0] * u.rad / u.day), InvalidStateError, r"\(2, 2\)"),
    ("zero spin has no mode", lambda: RotationState(BODY, IDENTITY, [0, 0, 0] * u.rad / u.day).mode, InvalidStateError, "zero spin"),
    ("Andoyer |L| > G", lambda: RotationState.from_andoyer(BODY, *[2.0, 1.0, 0.0] * u.rad / u.day, *[0, 0, 0] * u.rad), InvalidStateError, "L=2.0"),
    ("unknown reference", lambda: RotationState(BODY, IDENTITY, [0.1, 0.2, 1] * u.rad / u.day).canonical_elements(reference="icrs"), ValueError, "'icrs'"),
    ("elements of a permanent rotation", lambda: RotationState(BODY, IDENTITY, [0, 1.0, 0] * u.rad / u.day).canonical_elements(), SingularElementsError, "permanent rotation"),
    # --- paper-named core maps
    ("unordered moments", lambda: andoyer_to_canonical(0.3, 1, 0.2, 0.1, 0.2, 0.3, 2.0, 1.0, 2.5), ValueError, "A ≤ B ≤ C"),
    ("G negative", lambda: andoyer_to_canonical(0.3, -1, 0.2, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, "G ≤ 0"),
    ("|H| > G", lambda: andoyer_to_canonical(0.3, 1, 1.2, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, r"\|H\|"),
    ("NaN angle", lambda: andoyer_to_canonical(0.3, 1, 0.2, math.nan, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, "nan"),
    ("shapes do not broadcast", lambda: andoyer_to_canonical([0.3, 0.2], 1, [0.2, 0.1, 0], 0, 0, 0, 1.0, 2.0, 2.5), ValueError, r"L\(2,\)"),
    ("|S| above Z", lambda: canonical_to_andoyer(1.5, 1.0, 0.2, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, r"\[√\(A/C\) Z, Z\]"),
    ("Z zero", lambda: canonical_to_andoyer(0.5, 0.0, 0.0, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, "Z ≤ 0"),
    # --- torque-free arrays
    ("torque-free unordered moments", lambda: torque_free_states_many(np.array([IDENTITY]), np.array([[1, 0, 0.0]]), (2.0, 1.0, 3.0), [0.0]), ValueError, "A ≤ B ≤ C"),
    ("torque-free mismatched states", lambda: torque_free_states_many(np.array([IDENTITY]), np.zeros((2, 3)), (1.0, 2.0, 3.0), [0.0]), ValueError, r"\(2, 3\)"),
    # --- elliptic functions
    ("m negative", lambda: special.ellipj(0.3, -0.1), ValueError, "m = -0.1"),
    ("mc inconsistent", lambda: special.ellipj(0.3, 0.5, mc=0.1), ValueError, "mc = 0.1"),
    ("elliptic shapes", lambda: special.ellipj([0.1, 0.2], [0.1, 0.2, 0.3]), ValueError, r"u\(2,\)"),
    ("divergent characteristic", lambda: special.ellippi(1.5, 0.3, 0.5), ValueError, "n = 1.5"),
    # --- integrators and models
    ("rtol negative", lambda: integrate_quaternion(STATE, 0.0, np.array([1.0]), model(), rtol=-1), ValueError, "got -1"),
    ("rtol absurdly small", lambda: integrate_quaternion(STATE, 0.0, np.array([1.0]), model(), rtol=1e-30), ValueError, "1e-30"),
    ("output times not increasing", lambda: integrate_quaternion(STATE, 0.0, np.array([2.0, 1.0]), model()), ValueError, r"\[2.0, 1.0\]"),
    ("NaN in state", lambda: integrate_quaternion(np.r_[1, 0, 0, math.nan, 0.1, 0.2, 0.3], 0.0, np.array([1.0]), model()), ValueError, "nan"),
    ("zero quaternion in state", lambda: integrate_quaternion(np.r_[0, 0, 0, 0, 0.1, 0.2, 0.3], 0.0, np.array([1.0]), model()), ValueError, "non-zero quaternion"),
    ("negative moments in model", lambda: make_model((-1.0, 2.0, 3.0)), ValueError, "-1.0"),
    # --- time and ephemeris
    ("time as a float", lambda: so_time.tdb_days(2451545.0), TypeError, "float"),
    ("naive datetime", lambda: so_time.tdb_days(datetime.datetime(2000, 1, 1)), TypeError, "time scale"),
    ("unknown body", lambda: barycentric_state("vulcan", J2000), UnknownBodyError, "'vulcan'"),
    ("time after DE421", lambda: barycentric_state("earth", Time("2300-01-01", scale="tdb")), EphemerisRangeError, "1899-12-04 to 2200-02-01"),
    ("libration before DE421", lambda: moon_orientation(Time("1800-01-01", scale="tdb")), EphemerisRangeError, "outside DE421"),
]

# --- coupling to REBOUND (small two-body simulation; units of the simulation)
FIGURE = make_body((0.02, 0.03, 0.045), mass=0.3, reference_radius=0.3)


def two_bodies(integrator="bs"):
    import rebound

    sim = rebound.Simulation()
    sim.integrator = integrator
    sim.add(m=1.0, name="Planet")
    sim.add(m=0.3, a=3.0, name="Body")
    return sim


def attach(sim=None, body="Body", figure=FIGURE, state=STATE, **kwargs):
    return CoupledRigidBody(two_bodies() if sim is None else sim, body, figure, state, **kwargs)


def read_checkpoint_bytes(data: bytes, reader=Checkpoint.read):
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / "run.ckpt"
        path.write_bytes(data)
        return reader(path)


GOOD_CHECKPOINT = Checkpoint("coupled-rigid-body", {"y": np.arange(5.0)}).to_bytes()

CATALOGUE += [
    ("simulation without the body", lambda: attach(body="Phobos"), MissingBodyError, r"no particle named 'Phobos'.*\['Planet', 'Body'\]"),
    ("unknown perturber", lambda: attach(perturbers=["Deimos"]), MissingBodyError, "'Deimos'"),
    ("coupling under IAS15", lambda: attach(two_bodies("ias15")), ForceInstallError, "'bs' integrator, got"),
    ("rotation state of 6", lambda: attach(state=STATE[:6]), ValueError, "7 finite numbers"),
    ("NaN rotation state", lambda: attach(state=np.r_[STATE[:6], math.nan]), ValueError, "nan"),
    ("figure not a make_body array", lambda: attach(figure=[1.0, 2.0, 3.0]), ValueError, "make_body array"),
    ("body torques itself", lambda: attach(perturbers=["Body"]), ValueError, "cannot perturb itself"),
    ("DE421 simulation in 2300", lambda: simulation_from_de421(Time("2300-01-01", scale="tdb")), EphemerisRangeError, "2200-02-01"),
    ("DE421 simulation of Vulcan", lambda: simulation_from_de421(J2000, bodies=("sun", "vulcan")), UnknownBodyError, "'vulcan'"),
    ("DE421 epoch as a float (no time scale)", lambda: simulation_from_de421(2451545.0), TypeError, "float"),
    ("DE421 epoch array", lambda: simulation_from_de421(Time([2451545.0, 2451546.0], format="jd", scale="tdb")), TypeError, r"shape \(2,\)"),
    ("sample span in days, not Time", lambda: sample_from_ephemeris(de421_orbit("moon"), 0.0 * u.day, 10.0 * u.day), TypeError, "astropy Time"),
    ("sample span outside DE421", lambda: sample_from_ephemeris(de421_orbit("moon"), Time("2199-01-01", scale="tdb"), Time("2201-01-01", scale="tdb")), EphemerisRangeError, "leaves DE421's span"),
    ("unknown lunar model", lambda: moon_figure(1.0, model="jelly"), ValueError, "'jelly'"),
    ("lunar degree 7", lambda: moon_figure(1.0, degree=7), ValueError, "got 7"),
    ("one-way state not a RotationState", lambda: propagate_one_way(STATE, J2000, J2000, None), TypeError, "ndarray"),
    # --- absurd tolerances and chunks
    ("elements rtol 1e-30", lambda: integrate_elements(STATE, 0.0, np.array([1.0]), model(), rtol=1e-30), ValueError, "1e-30"),
    ("splitting step 0", lambda: integrate_splitting(STATE, 0.0, np.array([1.0]), model(), 0.0), ValueError, "got 0.0"),
    ("splitting step NaN", lambda: integrate_splitting(STATE, 0.0, np.array([1.0]), model(), math.nan), ValueError, "got nan"),
    ("resumable chunk 0", lambda: integrate_resumable("dop853", STATE, 0.0, [1.0], model(), chunk=0.0), ValueError, "got 0.0"),
    ("resumable unknown method", lambda: integrate_resumable("rk4", STATE, 0.0, [1.0], model(), chunk=1.0), ValueError, "'rk4'"),
    ("checkpoint every -1 s", lambda: CheckpointSchedule("x.ckpt", every_seconds=-1.0), ValueError, "got -1.0"),
    # --- unreadable, truncated, corrupted or foreign checkpoint files
    ("checkpoint missing", lambda: Checkpoint.read("/nonexistent/run.ckpt"), CheckpointError, "No such file"),
    ("checkpoint is a directory", lambda: Checkpoint.read(tempfile.gettempdir()), CheckpointError, "cannot read checkpoint"),
    ("checkpoint truncated", lambda: read_checkpoint_bytes(GOOD_CHECKPOINT[:-3]), CheckpointError, "promises 40 payload bytes, the file holds 37"),
    ("checkpoint bit flip", lambda: read_checkpoint_bytes(GOOD_CHECKPOINT[:-73] + b"\x01" + GOOD_CHECKPOINT[-72:]), CheckpointError, "SHA-256"),
    ("checkpoint is an npz", lambda: read_checkpoint_bytes(b"PK\x03\x04 zip data"), CheckpointError, "not a spinorbit checkpoint"),
    ("restore a truncated save", lambda: read_checkpoint_bytes(GOOD_CHECKPOINT[:-3], CoupledRigidBody.restore), RestoreError, "truncated"),
    ("resume a checkpoint of another kind", lambda: read_checkpoint_bytes(GOOD_CHECKPOINT, lambda p: integrate_to_outputs(None, [1.0], None, 4, resume=p)), CheckpointError, "'coupled-rigid-body' run; this run needs a 'coupled-run'"),
]


def test_catalogue_has_at_least_forty_cases():
    assert len(CATALOGUE) >= 40


@pytest.mark.parametrize("label, call, error, pattern", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_bad_input_is_refused_with_a_specific_message(label, call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()


# --- spinorbit moon: words, not tracebacks; exit status 2; nothing written
MOON_CASES = [
    ("span in kg", ["--span", "3", "kg"], "--span expects a time"),
    ("negative span", ["--span", "-1", "yr"], "--span: expected a positive number of days, got -365.25 d"),
    ("span past DE421", ["--span", "201", "yr"], "past DE421's last usable date 2200-01-31"),
    ("start before DE421", ["--start", "1899-01-01"], "--start: expected a date between 1899-12-05"),
    ("step longer than span", ["--span", "2", "d", "--step", "3", "d"], "up to the span (2 d), got 3.0 d"),
    ("step under a minute", ["--step", "1", "s"], "from 1 min"),
    ("unknown model", ["--model", "jelly"], "invalid choice: 'jelly'"),
    ("checkpoint every 0 s", ["--checkpoint", "{tmp}/run.ckpt", "--checkpoint-every", "0"], "positive number of seconds"),
    ("checkpoint every word", ["--checkpoint-every", "often"], "expected a number, got 'often'"),
    ("checkpoint into a missing directory", ["--checkpoint", "{tmp}/no/run.ckpt"], "does not exist"),
    ("resume a missing file", ["--resume", "{tmp}/none.ckpt"], "expects an existing checkpoint file"),
    ("resume a truncated file", ["--resume", "{tmp}/bad.ckpt"], "is truncated"),
    ("resume another kind", ["--resume", "{tmp}/other.ckpt"], "needs a 'coupled-run' checkpoint"),
    ("checkpoint with the de421 model", ["--model", "de421", "--checkpoint", "{tmp}/run.ckpt"],
     "apply to the REBOUND-coupled models"),
]


@pytest.mark.parametrize("label, argv, pattern", MOON_CASES, ids=[c[0] for c in MOON_CASES])
def test_moon_cli_bad_input_is_one_line_exit_2_and_no_output(capsys, tmp_path, label, argv, pattern):
    (tmp_path / "bad.ckpt").write_bytes(GOOD_CHECKPOINT[:-3])
    (tmp_path / "other.ckpt").write_bytes(GOOD_CHECKPOINT)
    before = sorted(tmp_path.iterdir())
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    try:
        # --model first: checkpoints belong to the REBOUND-coupled models; a case may override it.
        status = cli.main(["moon", "--model", "core-corrected", "--span", "2", "d", *argv,
                           "--output", str(tmp_path / "out.ecsv")])
    except SystemExit as exit_info:  # argparse's own checks exit from inside parse_args
        status = exit_info.code
    err = capsys.readouterr().err
    assert status == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("spinorbit moon: error:"), err
    assert pattern in lines[0]
    assert sorted(tmp_path.iterdir()) == before  # no output, no checkpoint, no temporary file


def test_moon_cli_refuses_to_resume_another_run(capsys, tmp_path):
    checkpoint = tmp_path / "run.ckpt"
    base = ["moon", "--model", "core-corrected", "--step", "1", "d", "--checkpoint-every", "1e-9"]
    assert cli.main([*base, "--span", "3", "d", "--checkpoint", str(checkpoint)]) == 0
    capsys.readouterr()
    assert cli.main([*base, "--span", "4", "d", "--resume", str(checkpoint)]) == 2
    err = capsys.readouterr().err.strip()
    assert "belongs to another run" in err and "span_days" in err and len(err.splitlines()) == 1
