"""Several rotating bodies in one :class:`~spinorbit.scene.Scene`: planned per body, sampled once per orbit.

``Scene([state_a, state_b], ...)`` or ``Scene({"a": state_a, "b": state_b}, ..., orbit={"a": orbit_a,
"b": orbit_b})``: every body gets its own plan (its own bounds, drops, route and integrator: they depend
on its moments and spin), and bodies that share an orbit (the *same* :class:`~spinorbit.scene.Orbit`
object: e.g. several candidate spin states or shape models of one asteroid) share its perturber
samples — the planner's survey is taken once, and the run samples the union of the perturbers the
bodies keep once, each body then using its own columns of it. The result is one table per body.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass

import numpy as np

from spinorbit.scene.inputs import Orbit, SceneError
from spinorbit.scene.sampling import SharedSamples

__all__ = ["ScenePlans", "SceneResults"]


@dataclass
class ScenePlans:
    """One :class:`~spinorbit.scene.plan.Plan` per body (``plans[name]``) and how the bodies share orbits."""

    plans: dict
    groups: list  # lists of body names sharing one orbit's samples

    def __getitem__(self, name):
        return self.plans[name]

    def __str__(self):
        shared = [g for g in self.groups if len(g) > 1]
        lines = [f"{len(self.plans)} bodies: " + (
            "; ".join(f"{', '.join(g)} share one orbit: the survey is taken once and the run samples the union of "
                      "their kept perturbers once" for g in shared) if shared else "no two share an orbit")]
        for name, plan in self.plans.items():
            lines.append(f"body {name}:")
            lines.extend("  " + line for line in str(plan).splitlines())
        return "\n".join(lines)


@dataclass
class SceneResults:
    """One :class:`~spinorbit.scene.SceneResult` per body (``results[name]``); ``tables[name]`` its table."""

    results: dict
    plan: ScenePlans
    wall_seconds: float

    def __getitem__(self, name):
        return self.results[name]

    @property
    def tables(self):
        """``{name: QTable}``, the bodies' tables."""
        return {name: result.table for name, result in self.results.items()}

    @property
    def tolerance_met(self):
        """True when every body's error estimate is within the tolerance."""
        return all(result.tolerance_met for result in self.results.values())


def members(states, orbit, make):
    """``{name: single-body Scene}`` from a sequence or mapping of states; ``make(state, orbit)`` builds one.

    Raises SceneError for an empty collection, a non-state, repeated names, or an orbit mapping that
    does not name every body.
    """
    from spinorbit.state import RotationState

    if isinstance(states, dict):
        named = dict(states)
    else:
        states = list(states)
        names = [getattr(s.body, "name", None) or f"body{i}" if isinstance(s, RotationState) else f"body{i}"
                 for i, s in enumerate(states)]
        if len(set(names)) != len(names):
            raise SceneError(f"states: the bodies' names {names} repeat; pass a mapping {{name: state}} instead.")
        named = dict(zip(names, states))
    if not named:
        raise SceneError("state expects a RotationState, or a non-empty sequence or mapping of them; got an empty one.")
    bad = {n: type(s).__name__ for n, s in named.items() if not isinstance(s, RotationState)}
    if bad:
        raise SceneError(f"state expects RotationStates for every body; got {bad}.")
    if isinstance(orbit, dict):
        missing = sorted(set(named) - set(orbit))
        extra = sorted(set(orbit) - set(named))
        if missing or extra:
            raise SceneError(f"orbit: a mapping must give one Orbit per body {sorted(named)}; missing {missing}, "
                             f"unknown {extra}.")
        orbits = orbit
    elif orbit is None or isinstance(orbit, Orbit):
        orbits = dict.fromkeys(named, orbit)
    else:
        raise SceneError(f"orbit expects an Orbit or a mapping {{body name: Orbit}}; got {type(orbit).__name__}.")
    return {name: make(state, orbits[name]) for name, state in named.items()}


def _groups(scenes):
    """Body names grouped by shared orbit (the same Orbit object, or none)."""
    groups = {}
    for name, scene in scenes.items():
        groups.setdefault(id(scene.orbit), []).append(name)
    return list(groups.values())


def plan_many(scenes, skip):
    """Plan every body, the bodies of one orbit sharing a sample cache (the survey is taken once)."""
    groups = _groups(scenes)
    plans = {}
    for group in groups:
        shared = SharedSamples()
        for name in group:
            with scenes[name].sharing_samples(shared):
                plans[name] = scenes[name].plan(skip)
    return ScenePlans({name: plans[name] for name in scenes}, groups)


def run_many(scenes, plans, progress):
    """Run every body's plan; per orbit, the union of the kept perturbers is sampled once for all bodies."""
    clock = _time.perf_counter()
    if not isinstance(plans, ScenePlans) or set(plans.plans) != set(scenes):
        raise SceneError(f"plan expects the ScenePlans of this scene's plan() (bodies {sorted(scenes)}); got "
                         f"{type(plans).__name__}.")
    report = progress or (lambda fraction: None)
    results, done = {}, 0
    for group in plans.groups:
        shared = SharedSamples()
        need = {}
        for name in group:
            plan, scene = plans[name], scenes[name]
            if plan.route == "one-way" and plan.samples is None:
                kept = [n for n in plan.kept if n in scene.named]
                if kept:
                    need.setdefault(plan.orbit_source, set()).update(kept)
        first = scenes[group[0]]
        for source, names in need.items():
            with first.sharing_samples(shared):  # one sampling of the union, in the bodies' perturber order
                first.sample_perturbers(source, [n for n in first.named if n in names], first.sample_tolerance)
        for name in group:
            with scenes[name].sharing_samples(shared):
                results[name] = scenes[name].run(plans[name])
            done += 1
            report(done / len(scenes))
    return SceneResults({name: results[name] for name in scenes}, plans, _time.perf_counter() - clock)


def common_times(scenes):
    """(epoch, times, tolerance_rad, output_days, epoch_day) of the bodies (all equal by construction)."""
    first = next(iter(scenes.values()))
    for name, scene in scenes.items():  # states that carry their own epochs must carry the same one
        if scene.epoch_day != first.epoch_day:
            raise SceneError(f"the bodies' states are at different epochs ({first.epoch.tdb.isot} and "
                             f"{scene.epoch.tdb.isot} TDB for {name!r}): a Scene of several bodies starts them at one "
                             "epoch. Give each state at the same epoch.")
    return first.epoch, first.times, first.tolerance_rad, np.asarray(first.output_days), first.epoch_day
