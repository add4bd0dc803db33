"""Members that run themselves: ensemble members that are not Scenes (``docs/ensembles.md``).

A member runs itself when ``make_scene(**row)`` returns an object (not a Scene) with an
``outcome_row(at_days)`` method: it runs when asked and returns its outcome as a dict of plain numbers,
strings and booleans, in the units the ensemble is given (``Ensemble(..., outcome_units=...)``). Such a
row crosses processes and checkpoints as a Scene's does. Example: :mod:`spinorbit.ensemble.dart`.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u

from spinorbit.ensemble.errors import EnsembleError

__all__ = ["checked_units", "own_columns", "own_row", "runs_itself"]


def runs_itself(member):
    """Whether ``member`` runs itself: not a Scene, but an object with ``outcome_row(at_days) -> dict``."""
    from spinorbit.scene import Scene

    return not isinstance(member, Scene) and callable(getattr(member, "outcome_row", None))


def own_row(member, at_days):
    """The outcome row of a member that runs itself, checked: a dict of plain numbers, strings, booleans."""
    row = member.outcome_row(at_days)
    plain = (bool, int, float, str, np.bool_, np.floating, np.integer)
    if not isinstance(row, dict) or not all(isinstance(k, str) and isinstance(v, plain) for k, v in row.items()):
        raise EnsembleError(f"{type(member).__name__}.outcome_row expects to return a dict of plain numbers, strings "
                            f"and booleans (units are the ensemble's outcome_units); got {row!r:.200}.")
    return {k: (v.item() if isinstance(v, np.generic) else v) for k, v in row.items()}


def checked_units(outcome_units):
    """``Ensemble(outcome_units=...)`` as a dict {column: unit}, or EnsembleError naming what arrived."""
    if outcome_units is not None and not (isinstance(outcome_units, dict) and all(
            isinstance(k, str) and isinstance(v, u.UnitBase) for k, v in outcome_units.items())):
        raise EnsembleError(f"outcome_units expects a dict {{column name: astropy unit}} (e.g. {{'period_change': "
                            f"u.min}}); got {outcome_units!r}.")
    return dict(outcome_units or {})


def own_columns(rows, standard):
    """The columns of members that run themselves beyond ``standard``, in the order the first row holding
    each gives them (rows: {index: row})."""
    own = []
    for index in sorted(rows):
        own += [name for name in rows[index] if name not in standard and name not in own and name != "ensemble_route"]
    return own
