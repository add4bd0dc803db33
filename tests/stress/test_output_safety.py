"""Outputs never destroy data (issue 14, class 3).

Generated file options for a real command (hypothesis draws what each of ``--output`` and
``--plot`` names: a new or existing file with any extension, the other option's file, a symbolic
link, a dangling link, a directory, a device, a missing directory). An oracle says whether the
run must be refused; refused runs exit 2 with one line and leave every file as it was, accepted
runs write the format the extension names. Checkpoint writes that fail on a real read-only
directory or on a file-size limit (the way a full disk fails a write) raise one
:class:`CheckpointError` and the previous checkpoint survives.
"""

import contextlib
import io
import os
import resource
import signal
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinorbit import cli
from spinorbit.runs.atomic import write_bytes_atomically
from spinorbit.runs.checkpoint import Checkpoint, CheckpointError

ROOT = Path(__file__).resolve().parents[2]
#: Examples of the generated CLI cases in the default run (≈ 0.3 s each: a run, a plot).
CLI_EXAMPLES = 40
TORQUE_FREE = ["torque-free", "--moments", "1", "2", "2.5", "--omega", "0.1", "0.2", "0.3", "--span", "1", "d",
               "--n-times", "5"]
#: What each accepted extension must put at the start of the file.
SIGNATURES = {".ecsv": b"# %ECSV", ".csv": b"time,", ".png": b"\x89PNG\r\n\x1a\n", ".pdf": b"%PDF-",
              ".svg": b"<?xml"}
TABLE_SUFFIXES, PLOT_SUFFIXES = (".ecsv", ".csv"), (".png", ".pdf", ".svg")
SUFFIXES = [".ecsv", ".csv", ".png", ".pdf", ".svg", ".PNG", ".txt", ".fits", ".ecsv.gz", ""]
KINDS = ["new", "existing", "same as the other", "symlink", "dangling symlink", "directory", "device",
         "missing directory"]


def snapshot(directory: Path) -> dict:
    """Every entry's type, link target and contents: what "left as it was" means."""
    state = {}
    for path in sorted(directory.rglob("*")):
        if path.is_symlink():
            state[path.name] = ("link", os.readlink(path))
        elif path.is_dir():
            state[path.name] = ("dir",)
        else:
            state[path.name] = ("file", path.read_bytes(), stat.S_IMODE(path.stat().st_mode))
    return state


def make_target(directory: Path, option: str, kind: str, suffix: str, other: str | None) -> tuple[str, bool]:
    """Create what ``kind`` says; return (path, whether the option may write it)."""
    name = directory / f"{option.strip('-')}{suffix}"
    allowed = suffix in (TABLE_SUFFIXES if option == "--output" else PLOT_SUFFIXES)
    if kind == "existing":
        name.write_bytes(b"previous results\n")
    elif kind == "same as the other" and other is not None:
        return other, False
    elif kind == "symlink":
        (directory / "target.dat").write_bytes(b"data the link points to\n")
        name.symlink_to(directory / "target.dat")
        return str(name), False
    elif kind == "dangling symlink":
        name.symlink_to(directory / "nowhere.dat")
        return str(name), False
    elif kind == "directory":
        name.mkdir()
        return str(name), False
    elif kind == "device":
        return os.devnull, False
    elif kind == "missing directory":
        return str(directory / "missing" / name.name), False
    return str(name), allowed


@settings(max_examples=CLI_EXAMPLES)
@given(st.sampled_from(KINDS), st.sampled_from(SUFFIXES), st.sampled_from(KINDS), st.sampled_from(SUFFIXES),
       st.booleans())
def test_generated_output_options_are_refused_up_front_or_written_in_their_format(
        output_kind, output_suffix, plot_kind, plot_suffix, with_plot):
    with tempfile.TemporaryDirectory() as name:
        directory = Path(name)
        output, output_ok = make_target(directory, "--output", output_kind, output_suffix, None)
        argv, expected = [*TORQUE_FREE, "--output", output], output_ok
        if with_plot:
            plot, plot_ok = make_target(directory, "--plot", plot_kind, plot_suffix, output)
            argv += ["--plot", plot]
            expected = expected and plot_ok
        before = snapshot(directory)
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            status = cli.main(argv)
        assert stat.S_ISCHR(os.stat(os.devnull).st_mode)  # the device is never replaced
        if not expected:
            assert status == 2, (argv, err.getvalue())
            lines = err.getvalue().strip().splitlines()
            assert len(lines) == 1 and lines[0].startswith("spinorbit torque-free: error: --"), lines
            assert snapshot(directory) == before
            return
        assert status == 0, err.getvalue()
        for path in [output] + ([plot] if with_plot else []):
            assert Path(path).read_bytes().startswith(SIGNATURES[Path(path).suffix])
        assert not [p for p in directory.iterdir() if p.name.startswith(".")]  # no temporary file left


@pytest.mark.parametrize("options", [
    ["--output", "{d}/a.ecsv", "--checkpoint", "{d}/a.ecsv"],
    ["--plot", "{d}/a.png", "--checkpoint", "{d}/a.png"],
    ["--output", "{d}/a.ecsv", "--resume", "{d}/a.ecsv"],
    ["--output", "{d}/a.ecsv", "--checkpoint", "{d}/sub/../a.ecsv"],
    ["--output", "{d}/link.ecsv", "--checkpoint", "{d}/a.ecsv"],
])
def test_moon_outputs_and_checkpoints_on_one_file_are_refused(tmp_path, capsys, options):
    (tmp_path / "sub").mkdir()
    (tmp_path / "a.ecsv").write_bytes(b"precious\n")
    (tmp_path / "link.ecsv").symlink_to(tmp_path / "a.ecsv")
    argv = ["moon", "--model", "core-corrected", "--span", "2", "d",
            *[o.replace("{d}", str(tmp_path)) for o in options]]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and ("name the same file" in err or "symbolic link" in err), err
    assert (tmp_path / "a.ecsv").read_bytes() == b"precious\n"


# ------------------------------------------------------------------------------- failed checkpoint writes
@contextlib.contextmanager
def read_only_directory(path: Path):
    """A directory nobody may create files in: chmod for users, the immutable attribute for root."""
    path.mkdir(exist_ok=True)
    if os.geteuid() == 0:
        made = subprocess.run(["chattr", "+i", str(path)], capture_output=True).returncode == 0
        undo = ["chattr", "-i", str(path)]
    else:
        os.chmod(path, 0o555)
        made, undo = True, None
    try:
        probe = path / "probe"
        try:
            probe.write_bytes(b"")
            probe.unlink()
            made = False
        except OSError:
            pass
        if not made:
            pytest.skip("cannot make a read-only directory here (no chattr for root)")
        yield path
    finally:
        if undo:
            subprocess.run(undo, check=False)
        else:
            os.chmod(path, 0o755)


PREVIOUS = Checkpoint("test", {"y": np.arange(4.0)}, {"chunk": 1})


def test_checkpoint_write_into_a_read_only_directory_keeps_the_previous_one(tmp_path):
    directory = tmp_path / "ro"
    directory.mkdir()
    PREVIOUS.write(directory / "run.ckpt")
    before = (directory / "run.ckpt").read_bytes()
    with read_only_directory(directory):
        with pytest.raises(CheckpointError, match="cannot write checkpoint .*previous checkpoint there.*unchanged"):
            Checkpoint("test", {"y": np.arange(8.0)}, {"chunk": 2}).write(directory / "run.ckpt")
        assert (directory / "run.ckpt").read_bytes() == before
        assert [p.name for p in directory.iterdir()] == ["run.ckpt"]


def test_moon_checkpoint_into_a_read_only_directory_is_one_line_and_keeps_the_previous_one(tmp_path, capsys):
    directory = tmp_path / "ro"
    directory.mkdir()
    checkpoint = directory / "run.ckpt"
    PREVIOUS.write(checkpoint)
    before = checkpoint.read_bytes()
    with read_only_directory(directory):
        status = cli.main(["moon", "--model", "core-corrected", "--span", "3", "d", "--checkpoint", str(checkpoint),
                           "--checkpoint-every", "1e-9"])
        err = capsys.readouterr().err.strip()
        # refused before the run (os.access sees chmod and the immutable attribute alike)
        assert status == 2 and len(err.splitlines()) == 1 and "is not writable" in err, err
        assert checkpoint.read_bytes() == before and [p.name for p in directory.iterdir()] == ["run.ckpt"]


def test_moon_checkpoint_write_failing_mid_run_is_one_line_and_keeps_the_previous_one(tmp_path, capsys):
    """The disk fills during the run: the checkpoint write fails after the up-front checks passed."""
    checkpoint = tmp_path / "run.ckpt"
    argv = ["moon", "--model", "core-corrected", "--span", "3", "d", "--checkpoint", str(checkpoint),
            "--checkpoint-every", "1e-9"]
    assert cli.main(argv) == 0  # also compiles everything, so nothing but the checkpoint is written below
    before = checkpoint.read_bytes()
    capsys.readouterr()
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (len(before) // 2, hard))
    try:
        status = cli.main(argv)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
        signal.signal(signal.SIGXFSZ, handler)
    err = capsys.readouterr().err.strip()
    assert status == 2 and len(err.splitlines()) == 1 and "cannot write checkpoint" in err, err
    assert "File too large" in err and "previous checkpoint there, if any, is unchanged" in err
    assert checkpoint.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["run.ckpt"]


#: A write beyond RLIMIT_FSIZE fails with EFBIG as a full disk fails with ENOSPC: midway, after part
#: of the data is on disk. The child writes a checkpoint larger than the limit over a smaller one.
FULL_DISK_CHILD = """
import resource, signal, sys
import numpy as np
from spinorbit.runs.checkpoint import Checkpoint, CheckpointError
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
try:
    Checkpoint("test", {"y": np.arange(4096.0)}).write(sys.argv[1])
except CheckpointError as error:
    print(error)
    sys.exit(2)
"""


@pytest.mark.parametrize("size_limited", [True])
def test_checkpoint_write_that_runs_out_of_space_keeps_the_previous_one(tmp_path, size_limited):
    target = tmp_path / "run.ckpt"
    PREVIOUS.write(target)
    before = target.read_bytes()
    child = subprocess.run([sys.executable, "-c", FULL_DISK_CHILD, str(target)], capture_output=True, text=True,
                           cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert child.returncode == 2, child.stderr
    assert "cannot write checkpoint" in child.stdout and "File too large" in child.stdout
    assert target.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["run.ckpt"]
    assert Checkpoint.read(target).meta == {"chunk": 1}


def test_api_writes_refuse_links_devices_and_directories(tmp_path):
    (tmp_path / "real.ckpt").write_bytes(b"keep")
    (tmp_path / "link.ckpt").symlink_to(tmp_path / "real.ckpt")
    for target, pattern in ((tmp_path / "link.ckpt", "symbolic link"), (os.devnull, "not a regular file"),
                            (tmp_path, "directory")):
        with pytest.raises(CheckpointError, match=pattern):
            PREVIOUS.write(target)
        with pytest.raises(OSError, match=pattern):
            write_bytes_atomically(target, b"x")
    assert (tmp_path / "real.ckpt").read_bytes() == b"keep" and (tmp_path / "link.ckpt").is_symlink()
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
