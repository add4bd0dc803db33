"""A rigid body whose rotation is integrated together with a REBOUND simulation's orbits.

Python-facing class over :func:`spinorbit.coupling.rebound.rotation_hooks.attach_rotation_hooks` (which owns
every raw pointer). Route and reasons: ``docs/coupling.md``. Units are the simulation's; for DE421
simulations (``simulation_from_de421``): au, day (TDB), Msun-mass units (GM/G), ω in rad/day.
"""

from __future__ import annotations

import numpy as np

from spinorbit.runs.checkpoint import CHECKPOINT_FORMAT_VERSION, Checkpoint, CheckpointError
from spinorbit.core.dynamics.equations import (
    body_frame_position,
    inertial_angular_momentum,
    kinetic_energy,
)
from spinorbit.core.model.gravity_field import figure_force_function_and_gradient
from spinorbit.coupling.rebound import (
    ExtraForces,
    MissingBodyError,
    RotationHooks,
    attach_rotation_hooks,
    body_index,
    integrate_interruptibly,
    step_interruptibly,
    reinstall_extra_forces,
    simulation_binary,
    simulation_from_binary,
)

__all__ = ["CHECKPOINT_KIND", "CONTENT_VERSION", "SAVE_FORMAT_VERSION", "CoupledRigidBody", "RestoreError"]

#: Version of the file format written by :meth:`CoupledRigidBody.save` (:mod:`spinorbit.runs.checkpoint`).
SAVE_FORMAT_VERSION = CHECKPOINT_FORMAT_VERSION
#: Version of what a body's checkpoint holds (``meta["content_version"]``). 2: the extra-force block
#: in effect (array ``extra_forces``). Version 1 (no ``content_version``) held only the ``earth_j2``/
#: ``gr`` arguments of the constructor and is refused: it cannot tell whether forces installed before
#: the body was attached (non-gravitational terms, J2, EIH) were acting.
CONTENT_VERSION = 2
#: ``kind`` of the checkpoints written by :meth:`CoupledRigidBody.checkpoint`.
CHECKPOINT_KIND = "coupled-rigid-body"


class RestoreError(CheckpointError):
    """A file is not a complete spinorbit coupled-rotation save (see :class:`CheckpointError`)."""


class CoupledRigidBody:
    """The rotation (q, ω) of one particle's figure, integrated with the orbits by REBOUND's BS.

    Parameters
    ----------
    sim : rebound.Simulation
        Integrator 'bs' (set ``sim.ri_bs.eps_abs``/``eps_rel``; 1e-13 for ephemeris work).
    body : str
        Name of the particle with the figure.
    figure : ndarray
        ``spinorbit.core.model.gravity_field.make_body`` array in simulation units (moments in
        mass·length², mass = the particle's mass, reference radius in length units).
    state : array_like, shape (7,)
        (q0, q1, q2, q3, ωx, ωy, ωz): q scalar first, body → inertial; ω body axes, rad/time unit.
    perturbers : sequence of str, optional
        Particles torquing the figure; default every other named particle.
    coupled : bool, optional
        True (default): the figure's back-reaction acts on the perturbers' orbits and the body's
        (energy and total angular momentum conserved). False: one-way (orbits ignore the figure).
    earth_j2, gr : bool, optional
        EIH 1PN and Earth J2 on the orbits, in the same compiled force (see ``install_extra_forces``).
        If ``install_extra_forces`` was called on ``sim`` before, its whole block (with any
        non-gravitational terms) is folded in instead; asking here for a force it lacks raises.
    earth_pole : array_like, shape (3,), optional
        Earth's figure axis for J2 (inertial unit vector).
    perturber_degrees : sequence of int, optional
        Highest degree of the figure's field each perturber sees (default: all of it).

    Raises
    ------
    spinorbit.coupling.rebound.simulation.MissingBodyError
        ``body`` or a perturber is not in the simulation.
    spinorbit.coupling.rebound.extra_forces.ForceInstallError
        The integrator is not BS, something else owns ``additional_forces``, or ``earth_j2``/``gr``
        asked for a force the block installed earlier does not have.
    """

    def __init__(self, sim, body, figure, state, perturbers=None, coupled=True, earth_j2=False, gr=False,
                 earth_pole=(0.0, 0.0, 1.0), perturber_degrees=None):
        centre = body_index(sim, body)
        if perturbers is None:
            perturbers = [p.name for i, p in enumerate(sim.particles) if i != centre and p.name]
        self.sim = sim
        self.body = sim.particles[centre].name
        self.perturbers = tuple(perturbers)
        self.hooks: RotationHooks = attach_rotation_hooks(
            sim, body, self.perturbers, figure, state, coupled=coupled, earth_j2=earth_j2, gr=gr,
            earth_pole=earth_pole, degrees=perturber_degrees,
        )
        self.perturber_degrees = self.hooks.perturber_degrees

    # ---------------------------------------------------------------------------------------
    @property
    def coupled(self) -> bool:
        """True if the figure acts back on the orbits."""
        return self.hooks.coupled

    @property
    def extra_forces(self) -> ExtraForces | None:
        """The extra forces acting on the orbits (a copy of their parameter block), or None.

        Those asked for here or installed with ``install_extra_forces`` before attaching: the
        forces in effect, which :meth:`checkpoint` stores.
        """
        return self.hooks.extra_forces

    @property
    def earth_j2(self) -> bool:
        """True if Earth's J2 acts on the orbits (whoever installed it)."""
        extra = self.extra_forces
        return extra is not None and extra.earth_j2

    @property
    def gr(self) -> bool:
        """True if the EIH 1PN accelerations act on the orbits (whoever installed them)."""
        extra = self.extra_forces
        return extra is not None and extra.gr

    @property
    def state(self) -> np.ndarray:
        """(q0..q3, ωx, ωy, ωz) at ``sim.t`` (a copy)."""
        return self.hooks.state

    @property
    def quaternion(self) -> np.ndarray:
        """Unit quaternion body → inertial, scalar first, at ``sim.t``."""
        q = self.hooks.state[:4]
        return q / np.linalg.norm(q)

    @property
    def omega(self) -> np.ndarray:
        """Body-frame angular velocity (rad per simulation time unit) at ``sim.t``."""
        return self.hooks.state[4:]

    @property
    def figure(self) -> np.ndarray:
        """The figure array (``gravity_field.make_body`` layout, simulation units), a copy."""
        return self.hooks.figure.copy()

    def integrate(self, t) -> None:
        """Advance orbits and rotation to time ``t`` (``exact_finish_time`` as set on ``sim``).

        Raises
        ------
        spinorbit.coupling.rebound.rotation_hooks.RotationCallbackError
            A compiled callback found a problem and stopped the run (message says what and when).
        KeyboardInterrupt
            Ctrl-C (SIGINT) during the call, also when REBOUND's own handler caught it.
        """
        integrate_interruptibly(self.sim, t)  # a Ctrl-C REBOUND absorbed still stops the run
        self.hooks.raise_if_failed()

    def step(self) -> None:
        """Advance orbits and rotation by one step of BS's own choosing (no output time cuts it).

        Raises
        ------
        spinorbit.coupling.rebound.rotation_hooks.RotationCallbackError, KeyboardInterrupt
            As :meth:`integrate`.
        """
        step_interruptibly(self.sim)
        self.hooks.raise_if_failed()

    # ---------------------------------------------------------------------------------------
    def figure_force_function(self) -> float:
        """U of the figure minus its monopole, summed over the perturbers (energy, sim units).

        The part of the mutual potential REBOUND's point-mass gravity does not contain.
        """
        q = self.quaternion
        sim = self.sim
        centre = body_index(sim, self.body)
        m_body = sim.particles[centre].m
        position = np.array(sim.particles[centre].xyz)
        total = 0.0
        for name in self.perturbers:
            particle = sim.particles[body_index(sim, name)]
            r = body_frame_position(q, np.array(particle.xyz) - position)
            mu = sim.G * particle.m
            u, _ = figure_force_function_and_gradient(r, mu, self.hooks.figure)
            total += u - mu * m_body / np.linalg.norm(r)
        return total

    def total_energy(self) -> float:
        """Orbital energy (REBOUND, point masses) + rotational kinetic energy − figure U (sim units).

        Conserved in the coupled mode without velocity-dependent extra forces.
        """
        y = self.state
        y[:4] /= np.linalg.norm(y[:4])
        return self.sim.energy() + kinetic_energy(y, self.hooks.figure) - self.figure_force_function()

    def total_angular_momentum(self) -> np.ndarray:
        """Orbital angular momentum (about the origin) + spin M(q) I ω, inertial frame (sim units)."""
        y = self.state
        y[:4] /= np.linalg.norm(y[:4])
        return np.array(self.sim.angular_momentum()) + inertial_angular_momentum(y, self.hooks.figure)

    # ---------------------------------------------------------------------------------------
    def checkpoint(self) -> Checkpoint:
        """Orbits + rotation + the forces in effect as one :class:`~spinorbit.runs.checkpoint.Checkpoint`.

        The REBOUND simulation in its binary form (``t``, particles, ``dt``, the integrator's
        settings and the BS controller's state: ``first_or_last_step``, ``previous_rejected``,
        ``target_iter``) and the rotation state travel together, so they cannot get out of step.
        REBOUND's binary holds neither user ODEs nor function pointers: the rotation state is stored
        next to it, and so is the extra-force parameter block acting on the orbits (EIH, Earth J2,
        non-gravitational terms), whether asked for in the constructor or installed before the body
        was attached; :meth:`from_checkpoint` re-installs both (meta ``content_version`` =
        :data:`CONTENT_VERSION`).
        """
        extra = self.extra_forces
        return Checkpoint(
            kind=CHECKPOINT_KIND,
            arrays={
                "simulation": np.frombuffer(simulation_binary(self.sim), dtype=np.uint8),
                "rotation_state": self.state,
                "figure": self.figure,
                "perturber_degrees": np.array(self.perturber_degrees, dtype=np.int64),
                # empty: no extra forces
                "extra_forces": np.zeros(0) if extra is None else extra.parameters,
            },
            meta={"content_version": CONTENT_VERSION, "body": self.body, "perturbers": list(self.perturbers),
                  "coupled": self.coupled,
                  # REBOUND's binary does not restore names reliably (simulation_from_binary)
                  "particle_names": [particle.name for particle in self.sim.particles]},
        )

    @classmethod
    def from_checkpoint(cls, checkpoint: Checkpoint) -> CoupledRigidBody:
        """Rebuild the simulation and its attached body from :meth:`checkpoint`; continues bit-for-bit.

        Raises
        ------
        RestoreError
            A checkpoint of another content version (message says why and what to do).
        """
        arrays, meta = checkpoint.arrays, checkpoint.meta
        version = meta.get("content_version", 1)
        if version == CONTENT_VERSION:  # a checksummed file may still have been edited by hand: its schema
            where = "<coupled-body checkpoint>"
            for name, dtype, shape in (("simulation", np.uint8, (None,)), ("rotation_state", np.float64, (7,)),
                                       ("figure", np.float64, (None,)), ("perturber_degrees", np.int64, (None,)),
                                       ("extra_forces", np.float64, (None,))):
                checkpoint.array(where, name, dtype, shape)
            for name, kind in (("body", str), ("perturbers", list), ("coupled", bool), ("particle_names", list)):
                checkpoint.setting(where, name, kind)
        if version != CONTENT_VERSION:
            why = ("it records only the earth_j2/gr arguments of the constructor, not the forces installed "
                   "with install_extra_forces/set_nongravitational before the body was attached, so a resume "
                   "could silently drop forces" if version == 1 else "this spinorbit does not know that layout")
            raise RestoreError(
                f"the coupled-body checkpoint has content version {version!r}, this spinorbit reads version "
                f"{CONTENT_VERSION} ({why}). Start the run again with this spinorbit, or resume with the "
                "version that wrote the checkpoint."
            )
        # REBOUND does not store function pointers or user ODEs: the extra forces in effect are
        # re-installed first, then the constructor attaches the ODE and folds them in, as the
        # uninterrupted run's combined force holds them (the same parameter block, bit for bit).
        sim = simulation_from_binary(arrays["simulation"].tobytes(), meta["particle_names"])
        first_or_last_step = sim.integrator.first_or_last_step  # the binary's; attaching resets it
        if arrays["extra_forces"].size:
            reinstall_extra_forces(sim, ExtraForces.from_parameters(arrays["extra_forces"]))
        try:
            body = cls(sim, meta["body"], arrays["figure"], arrays["rotation_state"], perturbers=meta["perturbers"],
                       coupled=meta["coupled"], perturber_degrees=[int(d) for d in arrays["perturber_degrees"]])
        except MissingBodyError as error:  # names in the checkpoint that its own simulation lacks: edited or foreign
            raise RestoreError(f"the coupled-body checkpoint names a body its simulation does not hold ({error}); "
                               "the file was edited or belongs to another run. Start the run again.") from None
        body.hooks.resume_bs_controller(sim, first_or_last_step)
        return body

    def save(self, path) -> None:
        """Write :meth:`checkpoint` to ``path`` atomically (temporary file, fsync, rename)."""
        self.checkpoint().write(path)

    @classmethod
    def restore(cls, path) -> CoupledRigidBody:
        """Rebuild a simulation and its attached body from :meth:`save`; continues bit-for-bit.

        Raises
        ------
        RestoreError
            Missing, unreadable, truncated or corrupted file, a checkpoint of another kind, or one
            of an older content version (:data:`CONTENT_VERSION`).
        """
        try:
            checkpoint = Checkpoint.read(path, kind=CHECKPOINT_KIND)
        except CheckpointError as error:
            raise RestoreError(str(error)) from None
        return cls.from_checkpoint(checkpoint)
