"""A state at its epoch, output times on either side of it: the run in two legs, backward and forward.

A published rotation state belongs to its epoch. When a :class:`~spinorbit.scene.Scene` is asked
for times before the epoch (or on both sides of it), it is split here into a **forward leg** (the
times after the epoch, an ordinary scene) and a **backward leg** run as a forward scene in mirrored
time: t′ = 2 t_epoch − t, ω′ = −ω, every orbit and perturber read at 2 t_epoch − t′ with its velocity
reversed. Euler's equations with a torque that depends on the attitude and the time only,
q̇ = ½ q ⊗ ω, I ω̇ = N(q, t) − ω × I ω, are invariant under that map (q′(t′) = q(t),
ω′(t′) = −ω(t)), so the mirrored leg is the backward run exactly, through the same planner,
bounds, integrators and a posteriori check. Each leg carries the whole tolerance (a row's error
comes from one leg); the error estimate is the larger of the two. A time equal to the epoch is the
state itself. The attitude at a given time therefore never depends on the span asked for
(``tests/test_scene_epochs.py``).

In the mirrored leg the perturbers are :class:`~spinorbit.scene.EphemerisPerturber` s, so a
backward leg never takes the coupled route (its back-reaction is not estimated there); a REBOUND
orbit is read through one integration of a copy for the body and all its perturbers at once.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.scene.inputs import EphemerisPerturber, Orbit, SceneError  # noqa: F401 (re-read by the legs)
from spinorbit.state import RotationState
from spinorbit.state_table import omega_array, quaternion_array
from spinorbit.time import time_from_tdb_days

__all__ = ["LegPlans", "mirrored_time", "plan_legs", "run_legs", "split_legs"]


def mirrored_time(epoch_day, days):
    """t′ = 2 t_epoch − t (TDB days): the map of the backward leg (it is its own inverse)."""
    return 2.0 * epoch_day - np.asarray(days, dtype=float)


def _mirrored_function(function, epoch_day):
    """``days′ -> (positions, velocities)`` of ``function`` read at the mirrored times, velocities reversed."""

    def mirrored(days):
        days = np.atleast_1d(np.asarray(days, dtype=float))
        positions, velocities = (np.asarray(a, dtype=float) for a in function(mirrored_time(epoch_day, days)))
        return positions, -velocities

    return mirrored


class _ReboundStates:
    """Barycentric states of several particles of one REBOUND run, one integration per set of times."""

    def __init__(self, simulation, names):
        self.simulation, self.names, self.key, self.states = simulation, tuple(names), None, None

    def __reduce__(self):
        # as Orbit: never REBOUND's raw simulation (its binary loses the forces), the description instead
        from spinorbit.scene.orbit import Orbit

        return (_rebound_states_of, (Orbit("rebound", self.names[0], simulation=self.simulation), self.names))

    def function(self, name):
        def states(days):
            days = np.atleast_1d(np.asarray(days, dtype=float))
            key = days.tobytes()
            if key != self.key:
                self.key, self.states = key, self._integrate(days)
            return self.states[name]

        return states

    def _integrate(self, days):
        from spinorbit.coupling.rebound import SimulationSnapshot, body_index, integrate_interruptibly

        index = {name: body_index(self.simulation, name) for name in self.names}
        run = SimulationSnapshot.of(self.simulation).build()
        out = {name: (np.empty((days.size, 3)), np.empty((days.size, 3))) for name in self.names}
        xyz, vel = np.zeros((run.N, 3)), np.zeros((run.N, 3))
        for j in np.argsort(days, kind="stable"):
            integrate_interruptibly(run, days[j])
            run.serialize_particle_data(xyz=xyz, vxvyvz=vel)
            for name, i in index.items():
                out[name][0][j], out[name][1][j] = xyz[i], vel[i]
        return out


def _rebound_states_of(orbit, names):
    return _ReboundStates(orbit.simulation, names)


def _mirrored_inputs(orbit, named, fixed, moving, epoch_day):
    """(orbit, perturbers) of the backward leg: the orbit and every perturber read in mirrored time."""
    from spinorbit.ephemeris import de421_constants

    perturbers = list(fixed)
    if orbit is None:
        body_function = None
    elif orbit.kind == "rebound":
        from spinorbit.coupling.rebound import body_index

        reader = _ReboundStates(orbit.simulation, (orbit.name, *named))
        body_function = reader.function(orbit.name)
        sim = orbit.simulation
        for name in named:
            gm = sim.particles[body_index(sim, name)].m * sim.G * u.au**3 / u.day**2
            perturbers.append(EphemerisPerturber(name, gm, _mirrored_function(reader.function(name), epoch_day)))
    else:
        from spinorbit.coupling.sampling import de421_orbit
        from spinorbit.scene.sampling import body_orbit

        body_function = body_orbit(orbit)
        gm_table = de421_constants().gm
        for name in named:
            perturbers.append(EphemerisPerturber(name, gm_table[name] * u.au**3 / u.day**2,
                                                 _mirrored_function(de421_orbit(name), epoch_day)))
    for user in moving:
        perturbers.append(EphemerisPerturber(user.name, user.gm, _mirrored_function(user.function, epoch_day),
                                             relative=user.relative))
    mirrored_orbit = None if body_function is None else Orbit(
        "ephemeris", orbit.name, function=_mirrored_function(body_function, epoch_day),
        description=f"{orbit.description or orbit.kind} (read backwards in time)")
    return mirrored_orbit, tuple(perturbers)


def split_legs(scene, make, perturbers, orbit):
    """Set ``scene`` (a :class:`~spinorbit.scene.Scene` whose times are not all after its epoch) up as two legs.

    ``make(state, epoch, times, perturbers, orbit)`` builds an ordinary Scene with the scene's
    tolerance, integrator and sample tolerance, asking for ω besides the scene's quantities (the rows
    are rebuilt from q and ω). Sets ``scene.backward``, ``scene.forward`` (None for an empty leg) and
    ``scene.at_epoch``.
    """
    epoch_day, output_days, state = scene.epoch_day, scene.output_days, scene.state
    epoch = time_from_tdb_days(epoch_day)
    before, after = output_days[output_days < epoch_day], output_days[output_days > epoch_day]
    scene.at_epoch = bool(np.any(output_days == epoch_day))
    scene.forward = make(state, epoch, time_from_tdb_days(after), perturbers, orbit) if after.size else None
    scene.backward = None
    if before.size:
        reversed_state = RotationState(state.body, state.quaternion, -state.angular_velocity)
        mirrored_orbit, mirrored_perturbers = _mirrored_inputs(orbit, scene.named, scene.fixed, scene.moving,
                                                               epoch_day)
        times = time_from_tdb_days(mirrored_time(epoch_day, before[::-1]))
        scene.backward = make(reversed_state, epoch, times, mirrored_perturbers, mirrored_orbit)


@dataclass
class LegPlans:
    """The plans of the two legs of a scene whose times lie on both sides of (or before) its epoch."""

    backward: object
    forward: object
    tolerance_rad: float
    backward_source: str = "none"

    @property
    def legs(self):
        return [(label, plan) for label, plan in (("backward", self.backward), ("forward", self.forward))
                if plan is not None]

    @property
    def route(self):
        return " / ".join(f"{label} {plan.route}" for label, plan in self.legs)

    @property
    def orbit_source(self):
        return " / ".join(f"{label} {self.backward_source if label == 'backward' else plan.orbit_source}"
                          for label, plan in self.legs)

    @property
    def integrator(self):
        return " / ".join(f"{label} {plan.integrator}" for label, plan in self.legs)

    @property
    def kept(self):
        return tuple(dict.fromkeys(name for _, plan in self.legs for name in plan.kept))

    @property
    def dropped(self):
        return tuple(name for name in dict.fromkeys(n for _, p in self.legs for n in p.dropped)
                     if name not in self.kept)

    def __str__(self):
        return "\n\n".join(f"{label} leg (times {'before' if label == 'backward' else 'after'} the epoch, "
                           f"run from the epoch):\n{plan}" for label, plan in self.legs)


def plan_legs(scene, skip):
    """Each leg's plan (:meth:`Scene.plan`), as one :class:`LegPlans`."""
    source = "none" if scene.orbit is None else f"{scene.orbit.kind} read backwards"
    return LegPlans(None if scene.backward is None else scene.backward.plan(skip),
                    None if scene.forward is None else scene.forward.plan(skip), scene.tolerance_rad, source)


def run_legs(scene, plan, progress, result_type, result_table):
    """Run both legs and join their rows in time order (``result_table`` builds the table of all rows)."""
    clock = _time.perf_counter()
    plan = plan_legs(scene, True) if plan is None else plan
    if not isinstance(plan, LegPlans):
        raise SceneError(f"plan expects the LegPlans of this scene's plan(); got {type(plan).__name__}.")
    report = progress or (lambda fraction: None)
    results, quaternions, omegas = {}, [], []
    share = 1.0 / max(len(plan.legs), 1)
    for k, (label, leg_plan) in enumerate(plan.legs):
        leg = getattr(scene, label)
        result = leg.run(leg_plan, progress=lambda f, k=k: report(share * (k + f)))
        results[label] = result
    if "backward" in results:
        table = results["backward"].table
        quaternions.append(quaternion_array(table)[::-1])
        omegas.append(-omega_array(table)[::-1])
    if scene.at_epoch:
        quaternions.append(scene.state.quaternion[None, :])
        omegas.append(scene.state.angular_velocity.to_value(u.rad / u.day)[None, :])
    if "forward" in results:
        table = results["forward"].table
        quaternions.append(quaternion_array(table))
        omegas.append(omega_array(table))
    table = result_table(scene, np.concatenate(quaternions), np.concatenate(omegas))
    # the obliquity on the scene's own orbit (a backward leg's mirrored orbit reverses the normal), the meta
    scene._complete_table(table, plan)
    # A row's error comes from its own leg: the estimate and its parts are the worse leg's (only the
    # epoch asked for: the state itself, no error).
    worst = max(results.values(), key=lambda result: result.error_estimate, default=None)
    parts = {"dropped": 0.0 * u.arcsec} if worst is None else dict(worst.error_parts)
    total = 0.0 * u.arcsec if worst is None else worst.error_estimate
    table.meta.update(error_estimate_arcsec=float(total.to_value(u.arcsec)), route=plan.route,
                      tolerance_met=bool(total.to_value(u.rad) <= plan.tolerance_rad))
    report(1.0)
    return result_type(table=table, error_estimate=total, error_parts=parts, plan=plan,
                       wall_seconds=_time.perf_counter() - clock,
                       stats={label: result.stats for label, result in results.items()})
