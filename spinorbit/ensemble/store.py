"""Checkpoints of an ensemble: one checksummed, atomic file per completed chunk in a directory.

Each completed chunk is written once, as a :class:`spinorbit.runs.checkpoint.Checkpoint` of kind
``"ensemble-chunk"`` (format 2: SHA-256 over every byte, header schema, written atomically), named
``chunk-<index>.ckpt``. Its meta holds the ensemble's fingerprint (make_scene's name, the parameter
rows, the chunk size and the outcome times), the chunk's member indices, the failures (index,
parameters, exception type and message) and the outcome rows' text columns; its arrays hold the
numeric columns with their exact bits. A resume reads every chunk file, refuses those of another
ensemble, and runs only the chunks that have none. A crash can lose at most the chunks under way.
"""

from __future__ import annotations

import os

import numpy as np

from spinorbit.runs.checkpoint import Checkpoint, CheckpointError

__all__ = ["CHUNK_KIND", "ChunkStore"]

CHUNK_KIND = "ensemble-chunk"


class ChunkStore:
    """Completed chunks of one ensemble (identified by ``fingerprint``) in ``directory``."""

    def __init__(self, directory, fingerprint):
        self.directory, self.fingerprint = os.fspath(directory), fingerprint
        if os.path.exists(self.directory) and not os.path.isdir(self.directory):
            raise CheckpointError(f"checkpoint expects a directory for the ensemble's chunk files; '{self.directory}' "
                                  "is a file. Give a directory path (it is created if missing).")
        os.makedirs(self.directory, exist_ok=True)

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
        if meta.get("fingerprint") != self.fingerprint or meta.get("chunk") != chunk:
            raise CheckpointError(f"checkpoint '{path}' belongs to another ensemble (its parameters, make_scene, "
                                  "chunk size or outcome times differ); give this ensemble its own checkpoint directory.")
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
