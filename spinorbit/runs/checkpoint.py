"""Checkpoint files: everything a long run needs to continue, in one self-checking file.

A checkpoint is a *kind* (which runner wrote it), a few named numpy arrays (states, bit for bit)
and a small JSON dictionary of settings. The file layout (format version 2)::

    spinorbit checkpoint\n                     magic line
    {"format_version": 2, "kind": ..., ...}\n   header: one line of JSON
    <payload>                                  the arrays' raw little-endian bytes, in header order
    sha256 <64 lowercase hex digits>\n          checksum of every byte above (magic, header, payload)

The checksum covers every byte a resume reads, so a flipped bit anywhere (header included), a
truncated copy or a file cut short by a full disk raises :class:`CheckpointError`. A file whose
checksum holds is then checked against the header's schema (:func:`validate_header`: types, dtypes
and byte order, names, shapes, byte counts, and their sum against the payload) before any array is
built, and each runner checks the arrays and settings it reads with :meth:`Checkpoint.array` and
:meth:`Checkpoint.setting` (a checkpoint edited and re-signed by hand, or one of another run, is
refused there). Arrays are stored raw (no text round trip), so floats come back with the same bits.
Writes go through :func:`spinorbit.runs.atomic.atomic_path`: a checkpoint on disk is always
complete, the previous one until the new one is in place, and a write that fails (read-only
directory, full disk) raises :class:`CheckpointError` and leaves the previous checkpoint as it was.

:class:`CheckpointSchedule` decides *when* a runner writes (every so many seconds of wall time
and/or every so many chunks); the runners decide *what* goes in (``docs/design.md``, "Checkpoints").
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import time
from dataclasses import dataclass, field

import numpy as np

from spinorbit.runs.atomic import write_bytes_atomically
from spinorbit.core.errors import SpinorbitError

__all__ = ["CHECKPOINT_FORMAT_VERSION", "Checkpoint", "CheckpointError", "CheckpointWriteError", "CheckpointSchedule",
           "RunStopped",
           "fingerprint", "validate_header"]

#: Version of the layout written by :meth:`Checkpoint.write`; :meth:`Checkpoint.read` accepts only it.
#: Version 1 (PR of issue 8) checksummed the payload only; its header was unprotected.
CHECKPOINT_FORMAT_VERSION = 2
MAGIC = b"spinorbit checkpoint\n"
#: Longest header accepted (bytes): a guard against reading a huge non-checkpoint file as JSON.
MAX_HEADER_BYTES = 1 << 20
#: The last line of a checkpoint: ``sha256 `` + 64 lowercase hex digits + newline.
TRAILER_PREFIX = b"sha256 "
TRAILER_BYTES = len(TRAILER_PREFIX) + 64 + 1
_TRAILER = re.compile(rb"sha256 [0-9a-f]{64}\n\Z")
#: dtype kinds a checkpoint may hold: bool, integers, floats, complex, fixed-width unicode.
_ALLOWED_KINDS = "biufcU"
#: The keys of a version-2 header, each with its JSON type; no other key is accepted.
HEADER_FIELDS = {"format_version": int, "kind": str, "meta": dict, "arrays": list, "payload_bytes": int}
#: Most arrays and most dimensions per array a header may list (a guard against absurd headers).
MAX_ARRAYS = 1024
MAX_DIMENSIONS = 8


class CheckpointError(SpinorbitError, ValueError):
    """A checkpoint file is missing, unreadable, truncated, corrupted, or belongs to another run."""


class CheckpointWriteError(CheckpointError):
    """A checkpoint cannot be written (the file a run writes, not the one it resumes from)."""


def fingerprint(*arrays) -> str:
    """SHA-256 (hex) of the bytes, dtypes and shapes of ``arrays``: identifies a run's inputs."""
    digest = hashlib.sha256()
    for array in arrays:
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def _little_endian(array: np.ndarray) -> np.ndarray:
    """The array with an explicit little-endian (or byte-order-free) dtype: files read the same everywhere."""
    if array.dtype.byteorder == ">" or (array.dtype.byteorder == "=" and np.little_endian is False):
        return array.astype(array.dtype.newbyteorder("<"))
    return array


def _strict_json(text: bytes):
    """JSON without NaN/Infinity and without repeated keys (both would make a header ambiguous)."""
    def no_constant(name):
        raise ValueError(f"the constant {name} is not allowed in a checkpoint header")

    def unique(pairs):
        keys = [key for key, _ in pairs]
        if len(set(keys)) != len(keys):
            raise ValueError(f"a key is repeated in {sorted(keys)}")
        return dict(pairs)

    return json.loads(text, parse_constant=no_constant, object_pairs_hook=unique)


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def validate_header(header) -> list[tuple[str, np.dtype, tuple, int]]:
    """Check a parsed header against the version-2 schema; return its array table.

    Returns
    -------
    list of (name, dtype, shape, nbytes)

    Raises
    ------
    ValueError
        Saying which field is wrong, what it should be and what it is.
    """
    if not isinstance(header, dict):
        raise ValueError(f"the header is a JSON {type(header).__name__}, not an object")
    if set(header) != set(HEADER_FIELDS):
        raise ValueError(f"the header has the keys {sorted(header)}, expected {sorted(HEADER_FIELDS)}")
    for key, kind in HEADER_FIELDS.items():
        if not isinstance(header[key], kind) or (kind is int and not _is_int(header[key])):
            raise ValueError(f"header field {key!r} is {header[key]!r}, expected a JSON {kind.__name__}")
    entries, total, names = [], 0, set()
    if len(header["arrays"]) > MAX_ARRAYS:
        raise ValueError(f"the header lists {len(header['arrays'])} arrays, more than {MAX_ARRAYS}")
    for position, entry in enumerate(header["arrays"]):
        where = f"array entry {position}"
        if not (isinstance(entry, list) and len(entry) == 4):
            raise ValueError(f"{where} is {entry!r}, expected [name, dtype, shape, nbytes]")
        name, dtype_text, shape, nbytes = entry
        if not isinstance(name, str) or not name or name in names:
            raise ValueError(f"{where}: name {name!r} is not a new non-empty string")
        names.add(name)
        if not (isinstance(dtype_text, str) and re.fullmatch(r"[<|][biufcU]\d{1,3}", dtype_text)):
            raise ValueError(f"{where} ({name!r}): dtype {dtype_text!r} is not a little-endian numeric or text "
                             "dtype such as '<f8'")
        try:
            dtype = np.dtype(dtype_text)
        except TypeError:
            raise ValueError(f"{where} ({name!r}): numpy does not know the dtype {dtype_text!r}") from None
        if dtype.kind not in _ALLOWED_KINDS or dtype.itemsize == 0 or dtype.str != dtype_text:
            raise ValueError(f"{where} ({name!r}): dtype {dtype_text!r} cannot be stored in a checkpoint")
        if not (isinstance(shape, list) and len(shape) <= MAX_DIMENSIONS
                and all(_is_int(n) and 0 <= n < 1 << 48 for n in shape)):
            raise ValueError(f"{where} ({name!r}): shape {shape!r} is not a list of at most {MAX_DIMENSIONS} "
                             "non-negative integers")
        expected = math.prod(shape) * dtype.itemsize
        if not _is_int(nbytes) or nbytes != expected:
            raise ValueError(f"{where} ({name!r}): {nbytes!r} bytes listed, its dtype and shape need {expected}")
        total += expected
        entries.append((name, dtype, tuple(shape), expected))
    if total != header["payload_bytes"]:
        raise ValueError(f"the arrays add up to {total} bytes, the header promises {header['payload_bytes']}")
    return entries


@dataclass(frozen=True)
class Checkpoint:
    """The state of an interrupted run: ``kind``, named arrays (exact) and JSON settings.

    Parameters
    ----------
    kind : str
        Which runner wrote it (e.g. ``"coupled-rebound"``, ``"core-integrator"``); a runner refuses
        a checkpoint of another kind.
    arrays : dict of str to ndarray
        Numeric (or fixed-width text) arrays, stored with their exact bits.
    meta : dict
        JSON-serialisable settings (names, flags, counters). Floats that must come back bit for bit
        belong in ``arrays``.
    """

    kind: str
    arrays: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    def to_bytes(self) -> bytes:
        """The file contents (magic line, JSON header, payload, checksum line)."""
        entries, chunks = [], []
        for name, value in self.arrays.items():
            array = _little_endian(np.ascontiguousarray(value))
            if array.dtype.kind not in _ALLOWED_KINDS:
                raise TypeError(f"checkpoint array {name!r}: dtype {array.dtype} cannot be stored; "
                                "use numbers, booleans or fixed-width strings.")
            data = array.tobytes()
            entries.append([str(name), array.dtype.str, list(array.shape), len(data)])
            chunks.append(data)
        payload = b"".join(chunks)
        header = {
            "format_version": CHECKPOINT_FORMAT_VERSION,
            "kind": self.kind,
            "meta": self.meta,
            "arrays": entries,
            "payload_bytes": len(payload),
        }
        body = MAGIC + json.dumps(header, sort_keys=True, allow_nan=False).encode() + b"\n" + payload
        return body + TRAILER_PREFIX + hashlib.sha256(body).hexdigest().encode() + b"\n"

    def write(self, path) -> None:
        """Write the checkpoint to ``path`` atomically (temporary file, fsync, rename).

        Raises
        ------
        CheckpointWriteError
            The file cannot be written (read-only directory, full disk, a directory in the way);
            the checkpoint previously at ``path``, if any, is unchanged.
        """
        data = self.to_bytes()
        try:
            write_bytes_atomically(path, data)
        except OSError as error:
            raise CheckpointWriteError(
                f"cannot write checkpoint '{os.fspath(path)}' ({error.strerror or error}); the previous checkpoint "
                "there, if any, is unchanged. Free disk space or choose a writable path."
            ) from None

    @classmethod
    def read(cls, path, kind: str | None = None) -> Checkpoint:
        """Read and verify a checkpoint written by :meth:`write`.

        Parameters
        ----------
        path : str or os.PathLike
        kind : str, optional
            Required kind; another kind raises.

        Raises
        ------
        CheckpointError
            The file is missing or unreadable, not a checkpoint, of another format version or kind,
            truncated, or its checksum does not match, or its header breaks the schema. The message
            names the file, what was expected and what was found, and what to do.
        """
        path = os.fspath(path)
        try:
            with open(path, "rb") as stream:
                # a foreign file (an image, a 50 GB log) is refused from its first bytes, not read whole
                data = stream.read(len(MAGIC))
                if data == MAGIC:
                    data += stream.read()
        except OSError as error:
            raise CheckpointError(
                f"cannot read checkpoint '{path}' ({error.strerror}); check the path, or start the run "
                "without resuming."
            ) from None
        return cls.from_bytes(data, path, kind)

    @classmethod
    def from_bytes(cls, data: bytes, path: str = "<bytes>", kind: str | None = None) -> Checkpoint:
        """Parse and verify checkpoint bytes (see :meth:`read`)."""
        restart = "resume from an earlier checkpoint or start the run again"
        if not data.startswith(MAGIC):
            raise CheckpointError(
                f"'{path}' is not a spinorbit checkpoint: expected it to start with {MAGIC!r}, found "
                f"{data[:len(MAGIC)]!r}{' (empty file)' if not data else ''}; give the file written by "
                "--checkpoint (or Checkpoint.write)."
            )
        end = data.find(b"\n", len(MAGIC), len(MAGIC) + MAX_HEADER_BYTES)
        if end < 0:
            raise CheckpointError(
                f"checkpoint '{path}' is truncated inside its header ({len(data)} bytes in all, no end of "
                f"header line); {restart}."
            )
        try:  # not yet verified: read only to word the errors below
            unverified = _strict_json(data[len(MAGIC):end])
        except (ValueError, RecursionError):
            unverified = None
        version = unverified.get("format_version") if isinstance(unverified, dict) else None
        if _is_int(version) and version != CHECKPOINT_FORMAT_VERSION:
            raise CheckpointError(
                f"checkpoint '{path}' has format version {version!r} (or is corrupted); this spinorbit reads version "
                f"{CHECKPOINT_FORMAT_VERSION}. Resume with the spinorbit version that wrote it, or start again."
            )
        promised = unverified.get("payload_bytes") if isinstance(unverified, dict) else None
        held = len(data) - (end + 1) - TRAILER_BYTES
        if _is_int(promised) and promised != held:
            what = "truncated" if held < promised else "longer than written"
            raise CheckpointError(
                f"checkpoint '{path}' is {what}: the header promises {promised} payload bytes, the file holds "
                f"{max(held, 0)} (before a {TRAILER_BYTES}-byte checksum line); {restart}."
            )
        body, trailer = data[:-TRAILER_BYTES], data[-TRAILER_BYTES:]
        if len(data) < end + 1 + TRAILER_BYTES or not _TRAILER.match(trailer):
            raise CheckpointError(
                f"checkpoint '{path}' has no valid checksum line at its end (truncated or corrupted); {restart}."
            )
        if hashlib.sha256(body).hexdigest().encode() != trailer[len(TRAILER_PREFIX):-1]:
            raise CheckpointError(
                f"checkpoint '{path}' is corrupted: the SHA-256 of its {len(body)} bytes (header and payload) does "
                f"not match the one recorded at its end when it was written; {restart}."
            )
        try:
            header = _strict_json(data[len(MAGIC):end])
            entries = validate_header(header)
        except (ValueError, RecursionError) as error:
            raise CheckpointError(f"checkpoint '{path}' has a corrupted header ({error}); {restart}.") from None
        if kind is not None and header["kind"] != kind:
            raise CheckpointError(
                f"checkpoint '{path}' was written by a {header['kind']!r} run; this run needs a {kind!r} "
                "checkpoint. Give the checkpoint of this kind of run."
            )
        payload = data[end + 1:len(data) - TRAILER_BYTES]
        arrays, offset = {}, 0
        for name, dtype, shape, nbytes in entries:
            count = nbytes // dtype.itemsize
            arrays[name] = np.frombuffer(payload, dtype=dtype, count=count, offset=offset).reshape(shape).copy()
            offset += nbytes
        return cls(kind=header["kind"], arrays=arrays, meta=header["meta"])

    def expect(self, path, what: str, found, expected) -> None:
        """Raise :class:`CheckpointError` unless ``found == expected`` (a resume with other settings)."""
        if found != expected:
            raise CheckpointError(
                f"checkpoint '{path}' belongs to another run: its {what} is {found!r}, this run has "
                f"{expected!r}. Resume with the settings of the interrupted run, or start a new run."
            )

    def array(self, path, name: str, dtype, shape) -> np.ndarray:
        """The array ``name``, checked to have ``dtype`` and ``shape`` (``None`` in ``shape``: any length).

        Raises
        ------
        CheckpointError
            The array is missing or of another dtype or shape: the checkpoint is not one this
            runner wrote (edited, or of another run).
        """
        dtype = np.dtype(dtype)
        value = self.arrays.get(name)
        if value is None:
            raise CheckpointError(f"checkpoint '{path}' has no array {name!r} (it holds {sorted(self.arrays)}); "
                                  "it was not written by this kind of run. Give the checkpoint of this run.")
        fits = value.ndim == len(shape) and all(want is None or want == got for want, got in zip(shape, value.shape))
        if value.dtype != dtype or not fits:
            wanted = "(" + ", ".join("any" if n is None else str(n) for n in shape) + ")"
            raise CheckpointError(
                f"checkpoint '{path}': array {name!r} is {value.dtype} of shape {value.shape}, this run needs {dtype} of "
                f"shape {wanted}; the file was edited or belongs to another run. Start the run again."
            )
        return value

    def setting(self, path, name: str, kind):
        """The meta value ``name``, checked to be of JSON type ``kind`` (int excludes bool)."""
        value = self.meta.get(name)
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
            raise CheckpointError(
                f"checkpoint '{path}': setting {name!r} is {value!r}, this run needs a {kind.__name__}; the file was "
                "edited or belongs to another run. Start the run again."
            )
        return value


class CheckpointSchedule:
    """When a runner writes its checkpoint: every ``every_seconds`` of wall time and/or ``every_chunks``.

    Parameters
    ----------
    path : str or os.PathLike
        The checkpoint file (overwritten atomically each time).
    every_seconds : float or None
        Wall-clock interval (s); default 60. None: no time trigger.
    every_chunks : int or None
        Write after this many chunks of simulated time; None: no chunk trigger.
    stop_after_chunks : int or None
        For tests and batch queues: stop the run (raise :class:`RunStopped`) right after writing
        the checkpoint at this chunk count, as if the process had been killed there.

    Raises
    ------
    ValueError
        Intervals that are not positive.
    """

    def __init__(self, path, every_seconds: float | None = 60.0, every_chunks: int | None = None,
                 stop_after_chunks: int | None = None):
        if every_seconds is not None and not (np.isfinite(every_seconds) and every_seconds > 0):
            raise ValueError(f"every_seconds: expected a positive wall-clock interval (s) or None, got {every_seconds!r}.")
        if every_chunks is not None and int(every_chunks) < 1:
            raise ValueError(f"every_chunks: expected a positive number of chunks or None, got {every_chunks!r}.")
        self.path = os.fspath(path)
        self.every_seconds = every_seconds
        self.every_chunks = None if every_chunks is None else int(every_chunks)
        self.stop_after_chunks = stop_after_chunks
        self._last_time = time.monotonic()
        self._last_chunk = 0

    def due(self, chunks_done: int) -> bool:
        """True if a checkpoint should be written now, after ``chunks_done`` chunks in all."""
        if self.stop_after_chunks is not None and chunks_done >= self.stop_after_chunks:
            return True
        if self.every_chunks is not None and chunks_done - self._last_chunk >= self.every_chunks:
            return True
        return self.every_seconds is not None and time.monotonic() - self._last_time >= self.every_seconds

    def write(self, checkpoint: Checkpoint, chunks_done: int) -> None:
        """Write ``checkpoint``; raise :class:`RunStopped` if the schedule says stop here."""
        checkpoint.write(self.path)
        self._last_time = time.monotonic()
        self._last_chunk = chunks_done
        if self.stop_after_chunks is not None and chunks_done >= self.stop_after_chunks:
            raise RunStopped(f"run stopped after {chunks_done} chunks; checkpoint in '{self.path}'.")


class RunStopped(Exception):
    """Raised by :class:`CheckpointSchedule` after the checkpoint at ``stop_after_chunks``."""
