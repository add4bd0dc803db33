"""Checkpoints of an ensemble: one checksummed, atomic file per completed chunk in a directory.

Each completed chunk is written once, as a :class:`spinorbit.runs.checkpoint.Checkpoint` of kind
``"ensemble-chunk"`` (format 2: SHA-256 over every byte, header schema, written atomically), named
``chunk-<index>.ckpt``. Its meta holds the ensemble's fingerprint (make_scene's name, the parameter
rows, the chunk size and the outcome times), the chunk's member indices, the failures (index,
parameters, exception type and message) and the outcome rows' text columns; its arrays hold the
numeric columns with their exact bits. A resume reads every chunk file, refuses those of another
ensemble, and runs only the chunks that have none. A crash can lose at most the chunks under way.

A directory belongs to one ensemble. Its manifest ``ensemble.ckpt`` (kind ``"ensemble-manifest"``,
written before the first chunk) holds the fingerprint, the ensemble's identity field by field
(:mod:`spinorbit.ensemble.identity`) and the seed entropy its parameters were drawn from, so that a
run of another ensemble is refused at once, saying which field differs, and a command can resume
without being given the seed again (:func:`stored_seed`). While a run uses the directory it holds
an exclusive lock on ``ensemble.lock`` (``flock``; the file holds the process id): a second run,
in this process or another, is refused instead of overwriting the first one's chunks. The lock goes
with the process, so a killed run leaves no stale lock (the file alone stays).
"""

from __future__ import annotations

import os

import numpy as np

from spinorbit.ensemble.identity import describe_differences
from spinorbit.runs.checkpoint import Checkpoint, CheckpointError

try:
    import fcntl
except ImportError:  # not POSIX: no lock, the manifest check still refuses another ensemble
    fcntl = None

__all__ = ["CHUNK_KIND", "LOCK_NAME", "MANIFEST_KIND", "MANIFEST_NAME", "ChunkStore", "stored_seed"]

CHUNK_KIND = "ensemble-chunk"
MANIFEST_KIND = "ensemble-manifest"
MANIFEST_NAME = "ensemble.ckpt"
LOCK_NAME = "ensemble.lock"


def _read_manifest(directory):
    path = os.path.join(os.fspath(directory), MANIFEST_NAME)
    return Checkpoint.read(path, kind=MANIFEST_KIND).meta if os.path.exists(path) else None


def stored_seed(directory):
    """The seed entropy (int) of the ensemble whose checkpoint directory is ``directory``, or None.

    None when the directory or its manifest does not exist, or its ensemble's parameters were not
    drawn from a seed; ``CheckpointError`` for a corrupted manifest.
    """
    if not os.path.isdir(os.fspath(directory)):
        return None
    manifest = _read_manifest(directory)
    seed = None if manifest is None else (manifest.get("identity") or {}).get("seed_entropy")
    return None if seed is None else int(seed)


class ChunkStore:
    """Completed chunks of one ensemble (identified by ``fingerprint``) in ``directory``.

    Used as a context manager (``with ChunkStore(...) as store``) it takes the directory for its
    ensemble: the lock, then the manifest checked (another ensemble's is refused) or written
    (module docstring). ``identity`` is the ensemble's
    :func:`~spinorbit.ensemble.identity.ensemble_identity`.
    """

    def __init__(self, directory, fingerprint, identity=None):
        self.directory, self.fingerprint, self.identity = os.fspath(directory), fingerprint, identity
        self._lock = None
        if os.path.exists(self.directory) and not os.path.isdir(self.directory):
            raise CheckpointError(f"checkpoint expects a directory for the ensemble's chunk files; '{self.directory}' "
                                  "is a file. Give a directory path (it is created if missing).")
        os.makedirs(self.directory, exist_ok=True)

    def __enter__(self):
        self._take_lock()
        try:
            self._own()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc_info):
        self.close()

    def close(self):
        """Release the directory's lock (the lock file stays; a lock is only held by an open file)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def _take_lock(self):
        if fcntl is None:
            return
        path = os.path.join(self.directory, LOCK_NAME)
        handle = open(path, "a+")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip() or "unknown"
            handle.close()
            raise CheckpointError(f"checkpoint directory '{self.directory}' is in use by another running ensemble "
                                  f"(process {holder} holds '{path}'); wait for it to finish, stop it, or give this "
                                  "run its own directory.") from None
        handle.seek(0)
        handle.truncate()
        handle.write(f"{os.getpid()}\n")
        handle.flush()
        self._lock = handle

    def _own(self):
        manifest = _read_manifest(self.directory)
        if manifest is None:
            Checkpoint(MANIFEST_KIND, {}, {"fingerprint": self.fingerprint, "identity": self.identity}).write(
                os.path.join(self.directory, MANIFEST_NAME))
        elif manifest.get("fingerprint") != self.fingerprint:
            self._refuse(os.path.join(self.directory, MANIFEST_NAME), manifest.get("identity"))

    def _refuse(self, path, stored_identity):
        why = ("its fingerprint (the file holds no identity to compare field by field)"
               if not isinstance(stored_identity, dict) or self.identity is None
               else "; ".join(describe_differences(stored_identity, self.identity)))
        raise CheckpointError(f"checkpoint '{path}' belongs to another ensemble: they differ in {why}. Give this "
                              "ensemble its own checkpoint directory, or run the ensemble the directory holds.")

    def path(self, chunk):
        return os.path.join(self.directory, f"chunk-{chunk:06d}.ckpt")

    def write(self, chunk, members, rows, failures):
        """Store chunk ``chunk``: ``rows`` {index: outcome dict}, ``failures`` {index: failure dict}."""
        names = sorted({name for row in rows.values() for name in row})
        done = [i for i in members if i in rows]
        arrays, text = {"members": np.asarray(members, dtype=np.int64), "done": np.asarray(done, dtype=np.int64)}, {}
        for name in names:
            values = [rows[i].get(name) for i in done]
            if any(isinstance(v, str) for v in values):
                text[name] = values
            elif any(isinstance(v, (bool, np.bool_)) for v in values):
                arrays[f"bool:{name}"] = np.asarray(values, dtype=bool)
            else:
                arrays[f"float:{name}"] = np.asarray([np.nan if v is None else v for v in values], dtype=float)
                arrays[f"present:{name}"] = np.asarray([v is not None for v in values], dtype=bool)
        meta = {"fingerprint": self.fingerprint, "chunk": int(chunk), "text": text,
                "failures": {str(i): f for i, f in failures.items()}}
        Checkpoint(CHUNK_KIND, arrays, meta).write(self.path(chunk))

    def read(self, chunk):
        """(rows, failures) of a stored chunk, or None when it has no file; CheckpointError for a foreign one."""
        path = self.path(chunk)
        if not os.path.exists(path):
            return None
        checkpoint = Checkpoint.read(path, kind=CHUNK_KIND)
        meta = checkpoint.meta
        if meta.get("fingerprint") != self.fingerprint:
            manifest = _read_manifest(self.directory)
            self._refuse(path, None if manifest is None or manifest.get("fingerprint") != meta.get("fingerprint")
                         else manifest.get("identity"))
        if meta.get("chunk") != chunk:
            raise CheckpointError(f"checkpoint '{path}' holds chunk {meta.get('chunk')!r}, not chunk {chunk} as its "
                                  "name says (a renamed or copied file); remove it to run that chunk again.")
        done = checkpoint.arrays["done"].tolist()
        rows = {i: {} for i in done}
        for key, values in checkpoint.arrays.items():
            kind, _, name = key.partition(":")
            if kind == "float":
                present = checkpoint.arrays[f"present:{name}"]
                for i, v, p in zip(done, values.tolist(), present.tolist()):
                    if p:
                        rows[i][name] = v
            elif kind == "bool":
                for i, v in zip(done, values.tolist()):
                    rows[i][name] = bool(v)
        for name, values in meta["text"].items():
            for i, v in zip(done, values):
                if v is not None:
                    rows[i][name] = v
        failures = {int(i): f for i, f in meta["failures"].items()}
        return rows, failures
