"""An ensemble's parameter table: one row per member, the columns make_scene's keyword arguments."""

from __future__ import annotations

import numpy as np
from astropy import units as u
from astropy.table import QTable

from spinorbit.ensemble.errors import EnsembleError

__all__ = ["parameter_table", "plain_value"]


def plain_value(value):
    """A parameter value as make_scene receives it: numpy scalars as Python numbers, Quantities as they are."""
    if isinstance(value, u.Quantity):
        return value
    if isinstance(value, np.generic):
        return value.item()
    return value


def parameter_table(parameters):
    """The ensemble's parameter table (a copy) from a QTable or a list of dicts with the same keys (EnsembleError)."""
    if isinstance(parameters, QTable):
        table = parameters.copy()
    elif isinstance(parameters, (list, tuple)) and parameters and all(isinstance(r, dict) for r in parameters):
        names = list(parameters[0])
        if any(list(r) != names for r in parameters):
            raise EnsembleError(f"parameters: every dict must have the same keys in the same order as the first "
                                f"({names}); pad the others or use a QTable.")
        table = QTable({name: u.Quantity([r[name] for r in parameters]) if isinstance(parameters[0][name], u.Quantity)
                        else np.array([r[name] for r in parameters]) for name in names})
    else:
        raise EnsembleError(f"parameters expects a QTable or a non-empty list of dicts (one per member); got "
                            f"{type(parameters).__name__}. For sampled parameters use Ensemble.sampled(...).")
    if len(table) == 0:
        raise EnsembleError("parameters has no rows: an ensemble needs at least one member.")
    return table
