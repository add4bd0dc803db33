"""What makes two ensembles the same: the fingerprint a checkpoint is checked against, and its fields.

The fingerprint (SHA-256) covers what fixes the results: ``make_scene``'s name, every parameter's
bits (the seed columns too), the member count, the chunk size, the route and the outcome times.
A checkpoint directory of another ensemble is refused; the *identity*, the same content field by
field (each parameter column digested on its own), lets the refusal say which field differs.
"""

from __future__ import annotations

import hashlib

import numpy as np
from astropy import units as u

__all__ = ["describe_differences", "ensemble_fingerprint", "ensemble_identity", "value_text"]


def value_text(value):
    """A parameter value as exact text: a float's hex digits, a Quantity's bits and unit, else its repr."""
    if isinstance(value, u.Quantity):
        return f"Q{np.asarray(value.value, dtype=float).tobytes().hex()}{value.unit}"
    if isinstance(value, float):
        return value.hex()
    return f"{type(value).__name__}{value!r}"


def _qualified(function):
    return f"{getattr(function, '__module__', '')}.{getattr(function, '__qualname__', '')}"


def _integrator_names(ensemble):
    return sorted((k, _qualified(f)) for k, f in (ensemble.batch_integrators or {}).items())


def ensemble_fingerprint(ensemble, columns):
    """SHA-256 (hex) of what fixes ``ensemble``'s results; ``columns`` as ``Ensemble._plain_columns`` gives them."""
    digest = hashlib.sha256()
    digest.update(f"{_qualified(ensemble.make_scene)}|{ensemble.chunk_size}|{ensemble.n_members}|".encode())
    if ensemble.route != "auto" or ensemble.batch_integrators is not None:  # the route decides the bits too
        digest.update(f"route={ensemble.route}|{_integrator_names(ensemble)}|".encode())
    if ensemble.at_days is not None:
        digest.update(ensemble.at_days.tobytes())
    for index in range(ensemble.n_members):
        digest.update("|".join(f"{name}={value_text(values[index])}" for name, values in columns.items()).encode())
    return digest.hexdigest()


def ensemble_identity(ensemble, columns):
    """The fingerprint's content field by field (JSON-ready): names and counts as they are, values digested."""
    def digest(texts):
        return hashlib.sha256("|".join(texts).encode()).hexdigest()[:16]

    seeds = columns.get("seed_entropy")
    return {"make_scene": _qualified(ensemble.make_scene), "members": ensemble.n_members,
            "chunk_size": ensemble.chunk_size, "route": ensemble.route,
            "batch_integrators": [list(pair) for pair in _integrator_names(ensemble)],
            "outcome_times": None if ensemble.at_days is None else digest([ensemble.at_days.tobytes().hex()]),
            "columns": {name: digest(value_text(v) for v in values) for name, values in columns.items()},
            "seed_entropy": None if not seeds else str(seeds[0])}


_LABELS = {"make_scene": "make_scene", "members": "member count", "chunk_size": "chunk size", "route": "route",
           "batch_integrators": "batch integrators", "outcome_times": "outcome times (at=)"}


def describe_differences(stored, current):
    """The fields in which identity ``current`` differs from ``stored``, in words (one clause each)."""
    clauses = []
    for key, label in _LABELS.items():
        if stored.get(key) != current.get(key):
            there, here = stored.get(key), current.get(key)
            clauses.append(f"{label} ({there} there, {here} here)" if key != "outcome_times" else label)
    there, here = stored.get("columns") or {}, current.get("columns") or {}
    if list(there) != list(here):
        clauses.append(f"parameter columns ({list(there)} there, {list(here)} here)")
    changed = [name for name in here if name in there and there[name] != here[name]]
    seeds = [name for name in changed if name.startswith("seed_")]
    others = [name for name in changed if not name.startswith("seed_")]
    if seeds:
        clauses.append(f"the members' seeds (seed entropy {stored.get('seed_entropy')} there, "
                       f"{current.get('seed_entropy')} here)")
    if others:
        clauses.append(f"the values of parameter {'column' if len(others) == 1 else 'columns'} {', '.join(others)}")
    return clauses or ["its fingerprint (the identity fields agree: the file was altered)"]
