"""Long runs lose nothing (issue 7): checkpoints, resume bit for bit, atomic output files.

An interrupted run goes through the checkpoint *file on disk* (written by the run, read back by a
new call or a new process) and must end with exactly the bits of the uninterrupted run: every
comparison here is ``==`` on float64 arrays, no tolerance.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from spinorbit.runs.atomic import atomic_path, write_bytes_atomically
from spinorbit.runs.checkpoint import (
    Checkpoint,
    CheckpointError,
    CheckpointSchedule,
    RunStopped,
)
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.model.gravity_field import make_body
from spinorbit.core.model.perturbers import kepler_source
from spinorbit.coupling.long_run import integrate_to_outputs
from spinorbit.coupling.rigid_body import CoupledRigidBody
from spinorbit.runs.resumable import METHODS, integrate_resumable

ROOT = Path(__file__).resolve().parent.parent
MOMENTS = (2.0 / 3.0, 1.0, 2.0)
Y0 = np.array([1.0, 0.0, 0.0, 0.0, 0.4 * np.sin(1.1) / MOMENTS[0], 0.0, np.cos(1.1) / MOMENTS[2]])
#: A perturber on an eccentric orbit: the torque changes along the run, so a chunk boundary matters.
MODEL = make_model(MOMENTS, [kepler_source(0.3, 4.0, 0.3, 0.4, 0.1, 0.2, 0.0)])
T_OUT = np.linspace(0.0, 60.0, 121)[1:]
OPTIONS = {"dop853": {"rtol": 1e-11}, "elements": {"rtol": 1e-11}, "splitting": {"step": 0.05}}


# ------------------------------------------------------------------------------------- format
def test_checkpoint_round_trip_keeps_bits_and_settings(tmp_path):
    arrays = {"y": np.array([np.pi, -0.0, 5e-324, np.nextafter(1.0, 2.0)]), "n": np.arange(3), "s": np.array(["ab"])}
    Checkpoint("test", arrays, {"name": "x", "k": 3}).write(tmp_path / "a.ckpt")
    back = Checkpoint.read(tmp_path / "a.ckpt", kind="test")
    assert back.meta == {"name": "x", "k": 3}
    for name, value in arrays.items():
        assert back.arrays[name].dtype == value.dtype and np.array_equal(back.arrays[name], value)
    assert np.array_equal(back.arrays["y"].view(np.uint64), arrays["y"].view(np.uint64))  # -0.0 kept


@pytest.mark.parametrize("damage, pattern", [
    (lambda b: b[:-7], "truncated: the header promises"),
    (lambda b: b[:30], "truncated inside its header"),
    (lambda b: b[:-73] + bytes([b[-73] ^ 1]) + b[-72:], "corrupted: the SHA-256"),  # last payload byte
    (lambda b: b[:-1] + bytes([b[-1] ^ 1]), "no valid checksum line"),
    (lambda b: b + b"x", "longer than written"),
    (lambda b: b"", "empty file"),
    (lambda b: b"PK\x03\x04" + b[4:], "not a spinorbit checkpoint"),
    (lambda b: b.replace(b'"format_version": 2', b'"format_version": 9'), "format version 9"),
    # the checksum covers the header too (format version 2): an edited key is caught by it
    (lambda b: b.replace(b'"payload_bytes"', b'"payload_bytez"'), "corrupted: the SHA-256"),
])
def test_damaged_checkpoints_raise_checkpoint_error_saying_what(tmp_path, damage, pattern):
    path = tmp_path / "a.ckpt"
    path.write_bytes(damage(Checkpoint("test", {"y": np.arange(10.0)}).to_bytes()))
    with pytest.raises(CheckpointError, match=pattern):
        Checkpoint.read(path)


def test_missing_checkpoint_and_wrong_kind(tmp_path):
    with pytest.raises(CheckpointError, match="cannot read checkpoint .*No such file"):
        Checkpoint.read(tmp_path / "none.ckpt")
    Checkpoint("test", {}).write(tmp_path / "a.ckpt")
    with pytest.raises(CheckpointError, match="written by a 'test' run; this run needs a 'other'"):
        Checkpoint.read(tmp_path / "a.ckpt", kind="other")


# ------------------------------------------------------------------------------------- atomic writes
class WriterFailed(Exception):
    pass


def test_failing_writer_leaves_no_file_and_keeps_the_old_one(tmp_path):
    target = tmp_path / "out.ecsv"
    with pytest.raises(WriterFailed), atomic_path(target) as temporary:
        Path(temporary).write_text("half a ta")
        raise WriterFailed
    assert list(tmp_path.iterdir()) == []
    target.write_text("old contents\n")
    os.chmod(target, 0o640)
    with pytest.raises(WriterFailed), atomic_path(target) as temporary:
        Path(temporary).write_text("half a ta")
        raise WriterFailed
    assert target.read_text() == "old contents\n" and [p.name for p in tmp_path.iterdir()] == ["out.ecsv"]
    write_bytes_atomically(target, b"new\n")
    assert target.read_bytes() == b"new\n" and (target.stat().st_mode & 0o777) == 0o640  # mode kept


def test_cli_outputs_fail_atomically(tmp_path, monkeypatch):
    """The ECSV writer of a real command fails midway: no file appears, an existing one is unchanged."""
    from astropy.io import ascii
    from astropy.table import Table

    from spinorbit import cli

    def failing_write(self, path, *args, **kwargs):
        ascii.write(self[:3], path, format="ecsv", overwrite=True)  # part of the table is on disk, then:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Table, "write", failing_write)
    output = tmp_path / "run.ecsv"
    argv = ["torque-free", "--moments", "1", "2", "2.5", "--omega", "0.1", "0.2", "0.3", "--span", "1", "d",
            "--step", "0.5", "d", "--output", str(output)]
    assert cli.main(argv) == 2
    assert list(tmp_path.iterdir()) == []
    output.write_text("previous run\n")
    assert cli.main(argv) == 2
    assert output.read_text() == "previous run\n" and len(list(tmp_path.iterdir())) == 1


# ------------------------------------------------------------------------------------- core integrators
@pytest.mark.parametrize("method", sorted(METHODS))
def test_core_integrator_resumed_from_file_ends_bit_for_bit(tmp_path, method):
    path = tmp_path / f"{method}.ckpt"
    whole = integrate_resumable(method, Y0, 0.0, T_OUT, MODEL, chunk=7.0, **OPTIONS[method])
    schedule = CheckpointSchedule(path, every_seconds=None, every_chunks=2, stop_after_chunks=3)
    with pytest.raises(RunStopped):
        integrate_resumable(method, Y0, 0.0, T_OUT, MODEL, chunk=7.0, schedule=schedule, **OPTIONS[method])
    assert Checkpoint.read(path).meta["chunks_done"] == 3
    resumed = integrate_resumable(method, Y0, 0.0, T_OUT, MODEL, chunk=7.0, resume=path, **OPTIONS[method])
    assert np.array_equal(resumed, whole)
    # The chunked run is a valid solution of the same problem: it agrees with one unchunked call
    # to the integrators' accuracy at rtol 1e-11 / step 0.05 over 60 time units (measured: 2.1e-10
    # dop853, 9.3e-12 elements, 1.0e-14 splitting, whose steps only shift at chunk ends): 20× margin.
    single = METHODS[method](Y0, 0.0, T_OUT, MODEL, **OPTIONS[method])
    assert np.max(np.abs(resumed - single)) < 5e-9


def test_core_resume_refuses_other_inputs(tmp_path):
    path = tmp_path / "run.ckpt"
    with pytest.raises(RunStopped):
        integrate_resumable("dop853", Y0, 0.0, T_OUT, MODEL, chunk=7.0,
                            schedule=CheckpointSchedule(path, None, 1, stop_after_chunks=1), rtol=1e-11)
    with pytest.raises(CheckpointError, match="belongs to another run: its inputs"):
        integrate_resumable("dop853", Y0, 0.0, T_OUT, MODEL, chunk=7.0, resume=path, rtol=1e-10)
    with pytest.raises(ValueError, match="chunk: expected a finite simulated time > 0"):
        integrate_resumable("dop853", Y0, 0.0, T_OUT, MODEL, chunk=-1.0)


# ------------------------------------------------------------------------------------- coupled REBOUND run
def _coupled_system():
    import rebound

    sim = rebound.Simulation()
    sim.integrator = "bs"
    sim.integrator.eps_abs = sim.integrator.eps_rel = 1e-12
    sim.add(m=1.0, name="Planet")
    sim.add(m=0.3, a=3.0, e=0.2, inc=0.3, name="Body")
    sim.move_to_com()
    sim.exact_finish_time = 1
    figure = make_body((0.02, 0.03, 0.045), mass=0.3, reference_radius=0.3)
    return CoupledRigidBody(sim, "Body", figure, [1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 2.0])


def _record(body):
    return np.concatenate([body.state, body.sim.particles["Body"].xyz])


def test_coupled_run_resumed_from_file_ends_bit_for_bit(tmp_path):
    times = np.linspace(0.0, 40.0, 41)[1:]
    path = tmp_path / "coupled.ckpt"
    body, rows, _ = integrate_to_outputs(_coupled_system(), times, _record, 10)
    schedule = CheckpointSchedule(path, every_seconds=None, every_chunks=5, stop_after_chunks=17)
    with pytest.raises(RunStopped):
        integrate_to_outputs(_coupled_system(), times, _record, 10, schedule=schedule, settings={"case": 1})
    resumed, resumed_rows, _ = integrate_to_outputs(None, times, _record, 10, resume=path, settings={"case": 1})
    assert np.array_equal(resumed_rows, rows)
    assert np.array_equal(resumed.state, body.state)
    for name in ("Planet", "Body"):
        a, b = body.sim.particles[name], resumed.sim.particles[name]
        assert a.xyz == b.xyz and a.vxyz == b.vxyz
    with pytest.raises(CheckpointError, match="its settings is"):
        integrate_to_outputs(None, times, _record, 10, resume=path, settings={"case": 2})


def _system_with_earlier_forces():
    """Sun, Earth and a small rotating body (au, day, Msun) with EIH, Earth J2 and A1/A2/A3 installed
    *before* the body is attached, as ``asteroids`` sets them up: the fold carries them into the
    body's combined force, and a checkpoint must carry them back."""
    import rebound

    from spinorbit.coupling.rebound import install_extra_forces, set_nongravitational

    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.integrator = "bs"
    sim.integrator.eps_abs = sim.integrator.eps_rel = 1e-12
    sim.add(m=1.0, name="Sun")
    sim.add(m=3e-6, a=1.0, e=0.0167, name="Earth")
    sim.add(m=1e-18, a=1.1, e=0.3, inc=0.2, name="Asteroid")
    sim.move_to_com()
    sim.exact_finish_time = 1
    install_extra_forces(sim, earth_j2=True, gr=True, earth_pole=(0.0, 0.6, 0.8))
    set_nongravitational(sim, "Asteroid", 3e-10, -2e-11, 1e-11)
    figure = make_body((4e-35, 5e-35, 6e-35), mass=1e-18, reference_radius=1e-8)
    return CoupledRigidBody(sim, "Asteroid", figure, [1.0, 0.0, 0.0, 0.0, 0.05, 0.1, 1.3],
                            perturbers=["Sun", "Earth"])


def test_resume_keeps_the_forces_installed_before_the_body_was_attached(tmp_path):
    """The checkpoint held only the constructor's earth_j2/gr (both off here): a resume ran without
    EIH, J2 and the non-gravitational terms (measured: 8.2e-8 au off the uninterrupted run 18 days
    after the restore at day 12). Also needs BS's first_or_last_step given back after the restore
    (``rotation_hooks._resume_bs_controller_cfunc``): without it this run left the uninterrupted one
    by ~1e-14 even with the forces right."""
    times = np.linspace(0.0, 30.0, 31)[1:]
    path = tmp_path / "forces.ckpt"
    record = lambda body: np.concatenate([body.state, body.sim.particles["Asteroid"].xyz])  # noqa: E731
    body, rows, _ = integrate_to_outputs(_system_with_earlier_forces(), times, record, 10)
    schedule = CheckpointSchedule(path, every_seconds=None, every_chunks=4, stop_after_chunks=12)
    with pytest.raises(RunStopped):
        integrate_to_outputs(_system_with_earlier_forces(), times, record, 10, schedule=schedule)
    resumed, resumed_rows, _ = integrate_to_outputs(None, times, record, 10, resume=path)
    assert np.array_equal(resumed_rows, rows)
    assert resumed.earth_j2 and resumed.gr  # the constructor was given neither
    assert np.array_equal(resumed.extra_forces.parameters, body.extra_forces.parameters)
    for name in ("Sun", "Earth", "Asteroid"):
        a, b = body.sim.particles[name], resumed.sim.particles[name]
        assert a.xyz == b.xyz and a.vxyz == b.vxyz


def test_checkpoints_of_the_old_content_refused_saying_why(tmp_path):
    """Version-1 body checkpoints (constructor flags only) cannot tell whether earlier forces acted."""
    from spinorbit.coupling.rigid_body import RestoreError

    current = _system_with_earlier_forces().checkpoint()
    arrays = {k: v for k, v in current.arrays.items() if k != "extra_forces"}
    arrays["earth_pole"] = np.array([0.0, 0.0, 1.0])
    meta = {k: v for k, v in current.meta.items() if k != "content_version"}
    meta.update(earth_j2=False, gr=False)
    Checkpoint(current.kind, arrays, meta).write(tmp_path / "old.ckpt")
    with pytest.raises(RestoreError, match="content version 1.*could silently drop forces.*Start the run again"):
        CoupledRigidBody.restore(tmp_path / "old.ckpt")
    assert issubclass(RestoreError, CheckpointError)


def _cli(*args):
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.Popen([sys.executable, "-m", "spinorbit", "moon", *args], cwd=ROOT, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@pytest.mark.slow
def test_moon_cli_killed_and_resumed_ends_bit_for_bit(tmp_path):
    """A real interruption: SIGKILL after the first checkpoint, resume in a new process (~30 s)."""
    span = ["--model", "core-corrected", "--span", "20", "yr"]
    full, resumed, checkpoint = tmp_path / "full.ecsv", tmp_path / "resumed.ecsv", tmp_path / "moon.ckpt"
    assert _cli(*span, "--output", str(full)).wait() == 0
    process = _cli(*span, "--output", str(resumed), "--checkpoint", str(checkpoint), "--checkpoint-every", "0.5")
    while not checkpoint.exists() and process.poll() is None:
        time.sleep(0.005)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert not resumed.exists(), "the run finished before it could be killed; lengthen --span"
    done = Checkpoint.read(checkpoint).meta["done"]
    assert 0 < done < 7306
    finish = _cli(*span, "--output", str(resumed), "--resume", str(checkpoint))
    assert finish.wait() == 0
    assert resumed.read_bytes() == full.read_bytes()


@pytest.mark.slow
def test_moon_cli_ctrl_c_names_the_checkpoint_to_resume_from(tmp_path):
    checkpoint = tmp_path / "moon.ckpt"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    process = subprocess.Popen([sys.executable, "-m", "spinorbit", "moon", "--model", "core-corrected", "--span", "50", "yr", "--checkpoint",
                                str(checkpoint), "--checkpoint-every", "0.2"], cwd=ROOT, env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    while not checkpoint.exists() and process.poll() is None:
        time.sleep(0.005)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate()
    assert process.returncode == 130
    assert f"--resume {checkpoint}" in err and "Traceback" not in err
    Checkpoint.read(checkpoint, kind="coupled-run")  # complete and readable


def test_ctrl_c_between_rebound_calls_is_not_lost():
    """REBOUND keeps its SIGINT handler installed after integrate() and zeroes its count at the next
    call; a real SIGINT sent between two calls must still stop the coupled run (and only once)."""
    body = _coupled_system()
    body.integrate(1.0)
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)  # Python handler (if REBOUND gave it back) or REBOUND's count: either stops
        body.integrate(2.0)
    body.integrate(3.0)  # the interrupt was consumed: the run can go on
    assert body.sim.t == 3.0


def test_restore_after_the_saved_simulation_is_freed_keeps_particle_names(tmp_path):
    """rebound 5.2.2 restores names as pointers into the saved simulation's memory (measured: 291 of
    300 restores misnamed a particle once it was freed); the checkpoint sets them again."""
    import gc

    path = tmp_path / "run.ckpt"
    for _ in range(20):
        body = _coupled_system()
        body.integrate(1.0)
        body.save(path)
        del body
        gc.collect()
        clutter = [bytes(64) + str(k).encode() for k in range(1000)]  # reuse the freed memory
        restored = CoupledRigidBody.restore(path)
        del clutter
        gc.collect()
        assert [p.name for p in restored.sim.particles] == ["Planet", "Body"]
        assert restored.sim.particles["Planet"].m == 1.0
