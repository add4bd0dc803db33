"""Copies of a REBOUND simulation: its binary, its particle names and the forces in effect.

REBOUND's binary holds particles, ``t``, ``G``, units, the integrator, its settings and its running
state, but neither function pointers nor user ODEs, and (rebound 5.2.2) the particles of a simulation
rebuilt from bytes keep name pointers into the memory of the simulation that was *saved*, which read
garbage once that one is freed. A copy is therefore three things: the binary, the names (set again
into memory the new simulation owns, :func:`simulation_from_binary`) and the extra-force block in
effect (:func:`extra_forces_in_effect`), reinstalled on the copy. :class:`SimulationSnapshot` holds
the three; the rigid-body checkpoint stores them too.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import rebound

from spinorbit.coupling.rebound.extra_forces import ExtraForces, ForceInstallError, reinstall_extra_forces
from spinorbit.coupling.rebound.rotation_hooks import RotationHooks

__all__ = ["simulation_binary", "simulation_from_binary", "extra_forces_in_effect", "SimulationSnapshot"]


def simulation_binary(sim) -> bytes:
    """REBOUND's binary form of ``sim`` (what ``rebound.Simulation(data)`` rebuilds), as bytes."""
    return sim.__reduce__()[1][0]


def simulation_from_binary(data: bytes, names):
    """A ``rebound.Simulation`` from :func:`simulation_binary` with the particles' ``names`` set again.

    Parameters
    ----------
    data : bytes
        REBOUND's binary of the simulation.
    names : sequence of str or None
        The particles' names in order (None for unnamed particles), as saved beside ``data``.

    Raises
    ------
    ValueError
        ``names`` does not have one entry per particle.
    """
    with warnings.catch_warnings():
        # REBOUND warns that function pointers are not restored: the caller re-attaches its forces.
        warnings.filterwarnings("ignore", message="You have to reset function pointers")
        sim = rebound.Simulation(data)
    names = list(names)
    if len(names) != sim.N:
        raise ValueError(f"names: expected one name per particle ({sim.N}), got {len(names)}.")
    for particle, name in zip(sim.particles, names):
        if name is not None:
            particle.name = name  # reb_particle_set_name: a copy owned by this simulation
    return sim


def extra_forces_in_effect(sim) -> ExtraForces | None:
    """The extra forces (EIH, Earth J2, non-gravitational) acting on ``sim``'s orbits now, as a copy.

    From :func:`~spinorbit.coupling.rebound.extra_forces.install_extra_forces` (and
    :func:`~spinorbit.coupling.rebound.extra_forces.set_nongravitational`) directly, or folded into a
    rigid body's combined force by :func:`~spinorbit.coupling.rebound.rotation_hooks.attach_rotation_hooks`.
    For rebuilding ``sim`` elsewhere (:func:`~spinorbit.coupling.rebound.extra_forces.reinstall_extra_forces`):
    a copy or a checkpoint that took only the attach arguments would lose the forces installed before
    the body.

    Raises
    ------
    ForceInstallError
        ``sim`` has forces spinorbit did not install (a Python ``additional_forces``, REBOUNDx, a
        pre/post-timestep hook): they cannot be carried to a rebuilt simulation.
    """
    handle = getattr(sim, "_afp", None)
    if isinstance(handle, ExtraForces):
        return ExtraForces.from_parameters(handle.parameters)
    if isinstance(handle, RotationHooks):
        return handle.extra_forces
    if handle is not None or sim._additional_forces or sim._pre_timestep_modifications \
            or sim._post_timestep_modifications or sim.extras:
        raise ForceInstallError(
            "the simulation has forces or hooks spinorbit did not install (a Python additional_forces, "
            "REBOUNDx or a timestep hook); a rebuilt copy would run without them. Use install_extra_forces "
            "and set_nongravitational for the forces, or sample the orbit yourself "
            "(spinorbit.coupling.sampling.sample_states)."
        )
    return None


@dataclass
class SimulationSnapshot:
    """Everything needed to rebuild a REBOUND simulation at one instant.

    REBOUND's own binary of the simulation, so that a copy has *all* of its settings, not a list of
    them that falls behind: particles, ``t``, ``G``, units, ``dt``, ``N_active``, softening, the
    integrator and its settings (BS ``eps_abs``, ``eps_rel``, ``min_dt``, ``max_dt``; IAS15
    ``epsilon``, ``min_dt``, ``adaptive_mode``) and its running state (the BS controller's flags,
    IAS15's predictor), so that a copy integrates bit for bit like the original
    (``tests/test_rebound_adapter.py``). The names are kept beside the binary, and the extra forces in
    effect (also those folded into an attached rigid body's force) are reinstalled on each copy. The
    rigid body itself (its user ODE and back-reaction) is not copied: copies are the orbits under
    point-mass gravity and the extra forces.

    Attributes
    ----------
    binary : bytes
        :func:`simulation_binary` of the simulation.
    names : tuple of str or None
        The particles' names, in order.
    extra_forces : ExtraForces or None
        The extra-force block in effect (:func:`extra_forces_in_effect`).
    """

    binary: bytes
    names: tuple
    extra_forces: ExtraForces | None

    @classmethod
    def of(cls, sim) -> SimulationSnapshot:
        """The snapshot of ``sim`` now (ForceInstallError for forces spinorbit cannot carry over)."""
        extra = extra_forces_in_effect(sim)
        return cls(simulation_binary(sim), tuple(p.name for p in sim.particles), extra)

    def build(self):
        """A new simulation at the snapshot, with ``exact_finish_time = 1`` (samples hit their times)."""
        sim = simulation_from_binary(self.binary, self.names)
        sim.exact_finish_time = 1
        if self.extra_forces is not None:
            # The raw force pointer does not survive a copy; reinstall the same forces (same
            # particle order, so the whole parameter block carries over: pole, Yarkovsky, ...).
            reinstall_extra_forces(sim, self.extra_forces)
        return sim
