"""A rigid body whose rotation is integrated together with a REBOUND simulation's orbits.

Python-facing class over :func:`spinorbit.coupling.rebound_adapter.attach_rotation_hooks` (which owns
every raw pointer). Route and reasons: ``docs/coupling.md``. Units are the simulation's; for DE421
simulations (``simulation_from_de421``): au, day (TDB), Msun-mass units (GM/G), ω in rad/day.
"""

from __future__ import annotations

import os
import tempfile
import warnings

import numpy as np
import rebound

from ..core.gravity_field import figure_force_function_and_gradient
from ..core.dynamics import body_frame_position, inertial_angular_momentum, kinetic_energy
from .rebound_adapter import (
    RotationHooks,
    attach_rotation_hooks,
    body_index,
)

__all__ = ["CoupledRigidBody", "SAVE_FORMAT_VERSION", "RestoreError"]

#: Version of the npz save format written by :meth:`CoupledRigidBody.save`.
SAVE_FORMAT_VERSION = 1


class RestoreError(ValueError):
    """A file is not a spinorbit coupled-rotation save (or has an unknown format version)."""


class CoupledRigidBody:
    """The rotation (q, ω) of one particle's figure, integrated with the orbits by REBOUND's BS.

    Parameters
    ----------
    sim : rebound.Simulation
        Integrator 'bs' (set ``sim.ri_bs.eps_abs``/``eps_rel``; 1e-13 for ephemeris work).
    body : str
        Name of the particle with the figure.
    figure : ndarray
        ``spinorbit.core.gravity_field.make_body`` array in simulation units (moments in
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
    earth_pole : array_like, shape (3,), optional
        Earth's figure axis for J2 (inertial unit vector).
    perturber_degrees : sequence of int, optional
        Highest degree of the figure's field each perturber sees (default: all of it).

    Raises
    ------
    spinorbit.coupling.rebound_adapter.MissingBodyError
        ``body`` or a perturber is not in the simulation.
    spinorbit.coupling.rebound_adapter.ForceInstallError
        The integrator is not BS, or something else owns ``additional_forces``.
    """

    def __init__(self, sim, body, figure, state, perturbers=None, coupled=True, earth_j2=False, gr=False,
                 earth_pole=(0.0, 0.0, 1.0), perturber_degrees=None):
        centre = body_index(sim, body)
        if perturbers is None:
            perturbers = [p.name for i, p in enumerate(sim.particles) if i != centre and p.name]
        self.sim = sim
        self.body = sim.particles[centre].name
        self.perturbers = tuple(perturbers)
        self.earth_j2, self.gr = bool(earth_j2), bool(gr)
        self.earth_pole = tuple(float(v) for v in earth_pole)
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
        spinorbit.coupling.rebound_adapter.RotationCallbackError
            A compiled callback found a problem and stopped the run (message says what and when).
        """
        self.sim.integrate(t)
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
    def save(self, path) -> None:
        """Write orbits + rotation + coupling settings to one ``.npz``, atomically.

        The REBOUND simulation (its binary form, including ``t`` and the integrator settings and
        step size) and the rotation state are in the same file, so they cannot get out of step.
        A temporary file in the same directory is renamed over ``path`` (no half-written file).
        """
        sim_bytes = self.sim.__reduce__()[1][0]
        directory = os.path.dirname(os.path.abspath(path)) or "."
        handle, temporary = tempfile.mkstemp(suffix=".npz", dir=directory)
        try:
            with os.fdopen(handle, "wb") as stream:
                np.savez(
                    stream,
                    format_version=np.int64(SAVE_FORMAT_VERSION),
                    simulation=np.frombuffer(sim_bytes, dtype=np.uint8),
                    rotation_state=self.state,
                    figure=self.figure,
                    body=np.str_(self.body),
                    perturbers=np.array(self.perturbers, dtype=str),
                    flags=np.array([self.coupled, self.earth_j2, self.gr]),
                    perturber_degrees=np.array(self.perturber_degrees, dtype=np.int64),
                    earth_pole=np.array(self.earth_pole),
                )
            os.replace(temporary, path)
        except BaseException:
            if os.path.exists(temporary):
                os.unlink(temporary)
            raise

    @classmethod
    def restore(cls, path) -> "CoupledRigidBody":
        """Rebuild a simulation and its attached body from :meth:`save`; continues bit-for-bit.

        Raises
        ------
        RestoreError
            Not a save of this kind, or an unknown format version.
        """
        try:
            with np.load(path, allow_pickle=False) as data:
                contents = {key: data[key] for key in data.files}
        except (OSError, ValueError) as error:
            raise RestoreError(f"{path}: not a readable spinorbit coupled-rotation save ({error}).") from None
        if "format_version" not in contents or int(contents["format_version"]) != SAVE_FORMAT_VERSION:
            raise RestoreError(f"{path}: expected format_version {SAVE_FORMAT_VERSION}.")
        with warnings.catch_warnings():
            # REBOUND warns that function pointers are not restored: the constructor below
            # re-attaches the ODE and the forces, which is exactly what the warning asks for.
            warnings.filterwarnings("ignore", message="You have to reset function pointers")
            sim = rebound.Simulation(contents["simulation"].tobytes())
        coupled, earth_j2, gr = (bool(v) for v in contents["flags"])
        return cls(sim, str(contents["body"]), contents["figure"], contents["rotation_state"],
                   perturbers=[str(n) for n in contents["perturbers"]], coupled=coupled,
                   earth_j2=earth_j2, gr=gr, earth_pole=contents["earth_pole"],
                   perturber_degrees=[int(d) for d in contents["perturber_degrees"]])
