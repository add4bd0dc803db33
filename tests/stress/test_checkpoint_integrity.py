"""Checkpoint integrity (issue 14, class 1): a corrupted, truncated, edited or foreign checkpoint is refused.

The checksum of format version 2 covers every byte a resume reads (magic line, header, payload),
so *every* single-bit flip and *every* truncation of a real checkpoint is tried here, not a
sample. A header edited and then re-signed (as a careless script or an adversary would) must still
be refused by the schema (hypothesis over the header's fields), and a schema-valid file of another
run by the runner's own checks. The command line reports all of it in one line with exit status 2.
"""

import hashlib
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinorbit import cli
from spinorbit.core.dynamics.equations import make_model
from spinorbit.runs.checkpoint import (
    MAGIC,
    TRAILER_BYTES,
    Checkpoint,
    CheckpointError,
    CheckpointSchedule,
    RunStopped,
)
from spinorbit.runs.resumable import RESUMABLE_KIND, integrate_resumable

MOMENTS = (2.0 / 3.0, 1.0, 2.0)
Y0 = np.array([1.0, 0.0, 0.0, 0.0, 0.3, 0.1, 0.5])
T_OUT = np.linspace(0.0, 4.0, 9)[1:]
#: Examples per hypothesis test over header fields (default run); the slow variant draws 20×.
HEADER_EXAMPLES = 150


def model():
    return make_model(MOMENTS)


def small_checkpoint() -> bytes:
    """A checkpoint with every kind of array the runners write (floats, ints, text, bool, 2-d, empty)."""
    return Checkpoint("test", {"y": np.array([np.pi, -0.0, 5e-324]), "n": np.arange(3, dtype=np.int64),
                               "s": np.array(["ab"]), "flag": np.array([True]), "m": np.eye(2),
                               "none": np.zeros(0)}, {"run": "abc", "k": 3}).to_bytes()


def resumable_checkpoint(tmp_path) -> tuple[bytes, dict]:
    """A real checkpoint of integrate_resumable after 2 of 4 chunks, and the call's arguments."""
    path = tmp_path / "run.ckpt"
    call = dict(method="dop853", y0=Y0, t0=0.0, t_out=T_OUT, model=model(), chunk=1.0, rtol=1e-10)
    with pytest.raises(RunStopped):
        integrate_resumable(**call, schedule=CheckpointSchedule(path, every_seconds=None, stop_after_chunks=2))
    return path.read_bytes(), call


def resign(header: dict, payload: bytes) -> bytes:
    """The file a script would write after editing the header: a fresh, *valid* checksum."""
    body = MAGIC + json.dumps(header, sort_keys=True).encode() + b"\n" + payload
    return body + b"sha256 " + hashlib.sha256(body).hexdigest().encode() + b"\n"


def split(data: bytes) -> tuple[dict, bytes]:
    end = data.index(b"\n", len(MAGIC))
    return json.loads(data[len(MAGIC):end]), data[end + 1:-TRAILER_BYTES]


# ------------------------------------------------------------------------------- bit flips, truncation
def test_every_bit_flip_of_a_checkpoint_is_refused():
    data = small_checkpoint()
    assert Checkpoint.from_bytes(data).meta == {"run": "abc", "k": 3}
    tried = 0
    for position in range(len(data)):
        for bit in range(8):
            damaged = bytearray(data)
            damaged[position] ^= 1 << bit
            with pytest.raises(CheckpointError):
                Checkpoint.from_bytes(bytes(damaged))
            tried += 1
    assert tried == 8 * len(data) > 3000


def test_every_truncation_and_extension_of_a_checkpoint_is_refused():
    data = small_checkpoint()
    for length in range(len(data)):
        with pytest.raises(CheckpointError):
            Checkpoint.from_bytes(data[:length])
    for tail in (b"\n", b"x", data[-TRAILER_BYTES:], b"\0" * 4096):
        with pytest.raises(CheckpointError):
            Checkpoint.from_bytes(data + tail)


def test_every_bit_flip_of_a_real_run_checkpoint_stops_the_resume(tmp_path):
    data, call = resumable_checkpoint(tmp_path)
    reference = integrate_resumable(**call)
    path = tmp_path / "damaged.ckpt"
    path.write_bytes(data)
    assert np.array_equal(integrate_resumable(**call, resume=path), reference)
    for position in range(len(data)):
        damaged = bytearray(data)
        damaged[position] ^= 1 << (position % 8)
        path.write_bytes(bytes(damaged))
        with pytest.raises(CheckpointError):
            integrate_resumable(**call, resume=path)


# ------------------------------------------------------------------------------- edited, re-signed headers
JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-2**70, 2**70) | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=12,
)
HEADER_KEYS = ("format_version", "kind", "meta", "arrays", "payload_bytes")
ENTRY_FIELDS = ("name", "dtype", "shape", "nbytes")
DTYPE_TEXTS = st.sampled_from(["<f8", ">f8", "=f8", "<f4", "|u1", "<i8", ">i8", "|b1", "<U2", "<U0", "|O",
                               "<M8", "<V8", "f8", "<c16", "<f16", "d", "<f8,<f8", "<S2"])


def _refused_or_consistent(data: bytes):
    """Either CheckpointError, or a Checkpoint whose arrays are exactly what its header lists."""
    try:
        checkpoint = Checkpoint.from_bytes(data)
    except CheckpointError:
        return False
    header, payload = split(data)
    assert [list(e[:1]) for e in header["arrays"]] == [[name] for name in checkpoint.arrays]
    assert sum(a.nbytes for a in checkpoint.arrays.values()) == len(payload)
    for name, dtype, shape, _ in header["arrays"]:
        assert checkpoint.arrays[name].dtype.str == dtype and list(checkpoint.arrays[name].shape) == shape
    return True


def _header_field_edit(key, value):
    header, payload = split(small_checkpoint())
    header[key] = value
    return resign(header, payload)


def _array_entry_edit(index, field, value):
    header, payload = split(small_checkpoint())
    header["arrays"][index % len(header["arrays"])][ENTRY_FIELDS.index(field)] = value
    return resign(header, payload)


@settings(max_examples=HEADER_EXAMPLES)
@given(st.sampled_from(HEADER_KEYS), JSON_VALUES)
def test_re_signed_header_with_any_field_edited_is_refused_or_consistent(key, value):
    _refused_or_consistent(_header_field_edit(key, value))


@settings(max_examples=HEADER_EXAMPLES)
@given(st.integers(0, 5), st.sampled_from(ENTRY_FIELDS), JSON_VALUES | DTYPE_TEXTS)
def test_re_signed_array_table_with_any_entry_edited_is_refused_or_consistent(index, field, value):
    _refused_or_consistent(_array_entry_edit(index, field, value))


@pytest.mark.slow
@settings(max_examples=20 * HEADER_EXAMPLES)
@given(st.sampled_from(HEADER_KEYS), JSON_VALUES, st.integers(0, 5), st.sampled_from(ENTRY_FIELDS),
       JSON_VALUES | DTYPE_TEXTS)
def test_re_signed_headers_thorough(key, value, index, field, entry_value):
    _refused_or_consistent(_header_field_edit(key, value))
    _refused_or_consistent(_array_entry_edit(index, field, entry_value))


@pytest.mark.parametrize("edit, pattern", [
    (lambda h: h["arrays"][0].__setitem__(1, ">f8"), "not a little-endian"),  # byte order
    (lambda h: h["arrays"][0].__setitem__(1, "|O"), "not a little-endian"),  # Python objects
    (lambda h: h["arrays"][0].__setitem__(2, [4]), "bytes listed, its dtype and shape need 32"),  # count
    (lambda h: h["arrays"][0].__setitem__(2, [1, -3]), "non-negative integers"),
    (lambda h: h["arrays"][0].__setitem__(3, 25.0), "bytes listed"),
    (lambda h: h["arrays"][1].__setitem__(0, "y"), "is not a new non-empty string"),  # repeated name
    (lambda h: h.__setitem__("payload_bytes", 1 << 62), "the header promises"),
    (lambda h: h.__setitem__("format_version", True), "expected a JSON int"),
    (lambda h: h.__setitem__("meta", [1, 2]), "expected a JSON dict"),
    (lambda h: h.__setitem__("extra", 1), "expected \\['arrays'"),
    (lambda h: h.pop("kind"), "expected \\['arrays'"),
])
def test_schema_names_the_broken_field(edit, pattern):
    header, payload = split(small_checkpoint())
    edit(header)
    with pytest.raises(CheckpointError, match=f"corrupted header.*{pattern}|{pattern}"):
        Checkpoint.from_bytes(resign(header, payload))


def test_repeated_keys_and_nan_in_a_re_signed_header_are_refused():
    header, payload = split(small_checkpoint())
    text = json.dumps(header, sort_keys=True)
    for edited in (text.replace('"kind": "test"', '"kind": "test", "kind": "other"'),
                   text.replace('"k": 3', '"k": NaN')):
        body = MAGIC + edited.encode() + b"\n" + payload
        data = body + b"sha256 " + hashlib.sha256(body).hexdigest().encode() + b"\n"
        with pytest.raises(CheckpointError, match="corrupted header"):
            Checkpoint.from_bytes(data)


# ------------------------------------------------------------------------------- foreign runs, schema-valid
@pytest.mark.parametrize("edit, pattern", [
    (lambda c: c.arrays.__setitem__("y", c.arrays["y"][:6]), "'y' is float64 of shape \\(6,\\)"),
    (lambda c: c.arrays.__setitem__("ys", c.arrays["ys"].astype(np.float32)), "'ys' is float32"),
    (lambda c: c.arrays.pop("t"), "has no array 't'"),
    (lambda c: c.meta.__setitem__("chunks_done", 99), "chunks_done = 99"),
    (lambda c: c.meta.__setitem__("chunks_done", "2"), "'chunks_done' is '2'"),
    (lambda c: c.meta.__setitem__("run", "0" * 64), "belongs to another run"),
    (lambda c: c.arrays.__setitem__("t", np.array([1.5])), "not this run's state"),
    (lambda c: c.arrays["y"].__setitem__(4, math.nan), "not this run's state"),
])
def test_resume_refuses_a_valid_checkpoint_that_is_not_this_runs(tmp_path, edit, pattern):
    data, call = resumable_checkpoint(tmp_path)
    checkpoint = Checkpoint.from_bytes(data, kind=RESUMABLE_KIND)
    edit(checkpoint)
    path = tmp_path / "edited.ckpt"
    checkpoint.write(path)
    with pytest.raises(CheckpointError, match=pattern):
        integrate_resumable(**call, resume=path)


# ------------------------------------------------------------------------------- the command line
def test_cli_resume_of_damaged_checkpoints_is_one_line_exit_2(tmp_path, capsys):
    checkpoint = tmp_path / "run.ckpt"
    base = ["moon", "--model", "core-corrected", "--step", "1", "d", "--span", "3", "d"]
    assert cli.main([*base, "--checkpoint", str(checkpoint), "--checkpoint-every", "1e-9"]) == 0
    data = checkpoint.read_bytes()
    capsys.readouterr()
    header_end = data.index(b"\n", len(MAGIC))
    # one flip in each part of the file, a truncation, a foreign file and an edited, re-signed header
    header, payload = split(data)
    header["meta"]["done"] = 10 ** 6
    variants = [bytes([data[0] ^ 4]) + data[1:], data[:30] + bytes([data[30] ^ 1]) + data[31:],
                data[:header_end + 9] + bytes([data[header_end + 9] ^ 128]) + data[header_end + 10:],
                data[:-5] + bytes([data[-5] ^ 2]) + data[-4:], data[:len(data) // 2], b"\x89PNG\r\n\x1a\n",
                resign(header, payload)]
    for damaged in variants:
        checkpoint.write_bytes(damaged)
        assert cli.main([*base, "--resume", str(checkpoint)]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
        assert err.startswith("spinorbit moon: error: ") and "run.ckpt" in err


def test_a_huge_foreign_file_is_refused_from_its_first_bytes(tmp_path):
    import time

    path = tmp_path / "huge.ckpt"
    with open(path, "wb") as stream:  # 8 GiB of zeros, sparse: nothing is written to disk
        stream.truncate(8 << 30)
    clock = time.perf_counter()
    with pytest.raises(CheckpointError, match="not a spinorbit checkpoint"):
        Checkpoint.read(path)
    assert time.perf_counter() - clock < 1.0  # not read whole
