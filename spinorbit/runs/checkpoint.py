"""Checkpoint files: everything a long run needs to continue, in one self-checking file.

A checkpoint is a *kind* (which runner wrote it), a few named numpy arrays (states, bit for bit)
and a small JSON dictionary of settings. The file layout (format version 1)::

    spinorbit checkpoint\\n                     magic line
    {"format_version": 1, "kind": ..., ...}\\n   header: one line of JSON
    <payload>                                  the arrays' raw bytes, in header order

The header lists every array (name, numpy dtype string, shape, byte count), the payload length and
the payload's SHA-256. :meth:`Checkpoint.read` checks all of them, so a truncated copy, a file cut
short by a full disk or a flipped bit raises :class:`CheckpointError` saying what was expected and
what arrived, instead of resuming from garbage. Arrays are stored raw (no text round trip), so
floats come back with the same bits. Writes go through :func:`spinorbit.runs.atomic.atomic_path`: a
checkpoint on disk is always complete, the previous one until the new one is in place.

:class:`CheckpointSchedule` decides *when* a runner writes (every so many seconds of wall time
and/or every so many chunks); the runners decide *what* goes in (``docs/design.md``, "Checkpoints").
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import dataclass, field

import numpy as np

from spinorbit.runs.atomic import write_bytes_atomically
from spinorbit.core.errors import SpinorbitError

__all__ = ["CHECKPOINT_FORMAT_VERSION", "Checkpoint", "CheckpointError", "CheckpointSchedule", "RunStopped",
           "fingerprint"]

#: Version of the layout written by :meth:`Checkpoint.write`; :meth:`Checkpoint.read` accepts only it.
CHECKPOINT_FORMAT_VERSION = 1
MAGIC = b"spinorbit checkpoint\n"
#: Longest header accepted (bytes): a guard against reading a huge non-checkpoint file as JSON.
MAX_HEADER_BYTES = 1 << 20
#: dtype kinds a checkpoint may hold: bool, integers, floats, complex, fixed-width unicode.
_ALLOWED_KINDS = "biufcU"


class CheckpointError(SpinorbitError, ValueError):
    """A checkpoint file is missing, unreadable, truncated, corrupted, or belongs to another run."""


def fingerprint(*arrays) -> str:
    """SHA-256 (hex) of the bytes, dtypes and shapes of ``arrays``: identifies a run's inputs."""
    digest = hashlib.sha256()
    for array in arrays:
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


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
        """The file contents (magic line, JSON header, payload)."""
        entries, chunks = [], []
        for name, value in self.arrays.items():
            array = np.ascontiguousarray(value)
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
            "sha256": hashlib.sha256(payload).hexdigest(),
        }
        return MAGIC + json.dumps(header, sort_keys=True).encode() + b"\n" + payload

    def write(self, path) -> None:
        """Write the checkpoint to ``path`` atomically (temporary file, fsync, rename)."""
        write_bytes_atomically(path, self.to_bytes())

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
            truncated, or its checksum does not match. The message names the file, what was
            expected and what was found, and what to do.
        """
        path = os.fspath(path)
        try:
            with open(path, "rb") as stream:
                data = stream.read()
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
        try:
            header = json.loads(data[len(MAGIC):end])
            version = header["format_version"]
            payload_bytes = int(header["payload_bytes"])
            entries = header["arrays"]
            checksum = header["sha256"]
        except (ValueError, KeyError, TypeError) as error:
            raise CheckpointError(f"checkpoint '{path}' has a corrupted header ({error}); {restart}.") from None
        if version != CHECKPOINT_FORMAT_VERSION:
            raise CheckpointError(
                f"checkpoint '{path}' has format version {version!r}; this spinorbit reads version "
                f"{CHECKPOINT_FORMAT_VERSION}. Resume with the spinorbit version that wrote it, or start again."
            )
        payload = data[end + 1:]
        if len(payload) != payload_bytes:
            what = "truncated" if len(payload) < payload_bytes else "longer than written"
            raise CheckpointError(
                f"checkpoint '{path}' is {what}: the header promises {payload_bytes} payload bytes, the file "
                f"holds {len(payload)}; {restart}."
            )
        if hashlib.sha256(payload).hexdigest() != checksum:
            raise CheckpointError(
                f"checkpoint '{path}' is corrupted: the SHA-256 of its {payload_bytes} payload bytes does not "
                f"match the one recorded when it was written; {restart}."
            )
        if kind is not None and header.get("kind") != kind:
            raise CheckpointError(
                f"checkpoint '{path}' was written by a {header.get('kind')!r} run; this run needs a {kind!r} "
                "checkpoint. Give the checkpoint of this kind of run."
            )
        arrays, offset = {}, 0
        try:
            for name, dtype, shape, nbytes in entries:
                dtype = np.dtype(dtype)
                if dtype.kind not in _ALLOWED_KINDS:
                    raise ValueError(f"dtype {dtype} is not allowed")
                count = int(np.prod(shape, dtype=np.int64))
                arrays[name] = np.frombuffer(payload, dtype=dtype, count=count, offset=offset).reshape(shape).copy()
                offset += int(nbytes)
        except (ValueError, TypeError) as error:
            raise CheckpointError(f"checkpoint '{path}' has a corrupted array table ({error}); {restart}.") from None
        return cls(kind=header["kind"], arrays=arrays, meta=header["meta"])

    def expect(self, path, what: str, found, expected) -> None:
        """Raise :class:`CheckpointError` unless ``found == expected`` (a resume with other settings)."""
        if found != expected:
            raise CheckpointError(
                f"checkpoint '{path}' belongs to another run: its {what} is {found!r}, this run has "
                f"{expected!r}. Resume with the settings of the interrupted run, or start a new run."
            )


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
