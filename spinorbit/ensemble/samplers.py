"""Parameters drawn at random for an ensemble, one seed per member, and the free motion's phases.

Every member draws its own values from its own seed: ``numpy.random.SeedSequence(seed).spawn(n)``
gives member ``i`` the sequence (entropy, spawn key ``(i,)``), so member ``i``'s parameters do not
depend on how many members there are, and a member is rebuilt alone from the two numbers the
result table records (``seed_entropy``, ``seed_spawn_key``; :func:`member_seed`).

The rotation phase of a tumbler is a point on the 2-torus of its free motion: the time along the
motion (a fraction of P_ψ: the body-frame spin's own cycle) and the angle of the body about its
fixed angular momentum (the precession's phase). :func:`state_at_phase` moves a state to any point
of it; both fractions uniform on [0, 1) is the uniform sampling of the rotation phase.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.table import QTable

from spinorbit.core.errors import SpinorbitError

__all__ = ["Normal", "SamplerError", "Uniform", "member_seed", "member_seeds", "sample_parameters", "state_at_phase"]

#: Columns of the per-member seed (strings: SeedSequence entropy may exceed 64 bits).
SEED_COLUMNS = ("seed_entropy", "seed_spawn_key")


class SamplerError(SpinorbitError, ValueError):
    """A distribution or a sample request is malformed."""


def _plain(value, name):
    """(float value, unit or None) of a number or scalar Quantity."""
    if isinstance(value, u.Quantity):
        if value.shape != () or not np.isfinite(value.value):
            raise SamplerError(f"{name} expects a finite scalar; got {value!r}.")
        return float(value.value), value.unit
    if isinstance(value, (int, float, np.floating, np.integer)) and np.isfinite(value):
        return float(value), None
    raise SamplerError(f"{name} expects a finite number or scalar Quantity; got {value!r}.")


@dataclass(frozen=True)
class Uniform:
    """Uniform on [low, high) (numbers or Quantities of one kind)."""

    low: object
    high: object

    def draw(self, rng):
        low, high, unit = _pair(self.low, self.high, "Uniform low", "Uniform high")
        if not low < high:
            raise SamplerError(f"Uniform expects low < high; got low={self.low!r}, high={self.high!r}.")
        return _with_unit(float(rng.uniform(low, high)), unit)


@dataclass(frozen=True)
class Normal:
    """Normal with ``mean`` and standard deviation ``sigma`` > 0 (numbers or Quantities of one kind)."""

    mean: object
    sigma: object

    def draw(self, rng):
        mean, sigma, unit = _pair(self.mean, self.sigma, "Normal mean", "Normal sigma")
        if not sigma > 0.0:
            raise SamplerError(f"Normal expects sigma > 0; got {self.sigma!r}.")
        return _with_unit(float(rng.normal(mean, sigma)), unit)


def _pair(first, second, first_name, second_name):
    """(first, second, unit or None): two numbers, or two Quantities of one kind in the first's unit."""
    value, unit = _plain(first, first_name)
    if unit is not None and not isinstance(second, u.Quantity):
        raise SamplerError(f"{second_name} expects a Quantity like {first_name} ({first!r}); got {second!r}.")
    other = _plain(u.Quantity(second).to(unit) if unit is not None else second, second_name)[0]
    return value, other, unit


def _with_unit(value, unit):
    return value * unit if unit is not None else value


def member_seeds(n, seed):
    """(root entropy as int, list of n child SeedSequences) of ``SeedSequence(seed).spawn(n)``."""
    root = np.random.SeedSequence(seed)
    return int(root.entropy), root.spawn(n)


def member_seed(entropy, spawn_key):
    """The SeedSequence of one member from its recorded ``seed_entropy`` and ``seed_spawn_key``."""
    return np.random.SeedSequence(int(entropy), spawn_key=(int(spawn_key),))


def sample_parameters(n, seed=None, **distributions):
    """A parameter table of ``n`` members, each drawing ``distributions`` (in the order given) from its own seed.

    Parameters
    ----------
    n : int
        Number of members (≥ 1).
    seed : int or None
        Root of :class:`numpy.random.SeedSequence`; None draws fresh entropy (recorded in the table).
    **distributions : Uniform, Normal, or a constant
        Column name → distribution; a constant is repeated in every row.

    Returns
    -------
    QTable
        One column per distribution, then ``seed_entropy`` and ``seed_spawn_key`` (strings and ints;
        :func:`member_seed` rebuilds a member's SeedSequence from them). ``meta["seed_entropy"]``
        holds the root entropy.
    """
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise SamplerError(f"n expects a positive number of members; got {n!r}.")
    if not distributions:
        raise SamplerError("sample_parameters needs at least one distribution, e.g. phase=Uniform(0, 1).")
    entropy, children = member_seeds(int(n), seed)
    rows = []
    for child in children:
        rng = np.random.default_rng(child)
        rows.append({name: (d.draw(rng) if hasattr(d, "draw") else d) for name, d in distributions.items()})
    table = QTable({name: u.Quantity([row[name] for row in rows]) if isinstance(rows[0][name], u.Quantity)
                    else np.array([row[name] for row in rows]) for name in distributions})
    table["seed_entropy"] = np.array([str(entropy)] * int(n))
    table["seed_spawn_key"] = np.array([child.spawn_key[-1] for child in children], dtype=np.int64)
    table.meta["seed_entropy"] = str(entropy)
    return table


def state_at_phase(state, fraction_of_p_psi=0.0, fraction_about_momentum=0.0):
    """``state`` moved to another point of the torus of its free motion (the same motion, another phase).

    Parameters
    ----------
    state : RotationState
    fraction_of_p_psi : float in [0, 1)
        Time along the free motion (paper eq. 12) as a fraction of P_ψ (``state.periods[0]``).
    fraction_about_momentum : float in [0, 1)
        Rotation of the whole body about its (fixed, inertial) angular momentum by 2π × this fraction:
        the precession's phase. Body-frame spin, mode, periods and pole are unchanged.

    The result keeps ``state.epoch``: it is another phase of the motion at the same instant.

    Returns
    -------
    RotationState
    """
    from spinorbit.state import RotationState

    for name, value in (("fraction_of_p_psi", fraction_of_p_psi), ("fraction_about_momentum", fraction_about_momentum)):
        if not (isinstance(value, (int, float, np.floating)) and 0.0 <= value < 1.0):
            raise SamplerError(f"{name} expects a fraction in [0, 1); got {value!r}.")
    if fraction_of_p_psi:
        quaternions, omegas = state.propagate_torque_free(fraction_of_p_psi * state.periods[0])
        state = RotationState(state.body, quaternions[0], omegas[0], epoch=state.epoch)  # another phase, same epoch
    if fraction_about_momentum:
        turn = _turn_about(state.angular_momentum_direction, 2.0 * np.pi * float(fraction_about_momentum))
        # R' = R Tᵀ: the body turned by T about L; R' L = R L, so the body-frame momentum is unchanged
        state = RotationState.from_matrix(state.body, state.attitude_matrix @ turn.T, state.angular_velocity, state.epoch)
    return state


def _turn_about(axis, angle):
    """The active rotation matrix by ``angle`` (rad) about the unit ``axis`` (Rodrigues' formula)."""
    x, y, z = axis
    cross = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * (cross @ cross)
