"""A run described declaratively, and the planner that decides how to run it.

:class:`Scene` says what a run needs — body, perturbers, orbit, output times, tolerance; its
``plan()`` decides cheapest-first and says why, ``run()`` does it (``docs/scenes.md``).

One module per concept:

- :mod:`~spinorbit.scene.orbit` — :class:`Orbit`: where the body's orbit comes from (DE421, an
  ephemeris, a REBOUND run, published elements or a state vector) and its close approaches;
- :mod:`~spinorbit.scene.inputs` — :class:`FixedPerturber`, :class:`EphemerisPerturber`
  and the checks of a scene's arguments (:class:`SceneError`);
- :mod:`~spinorbit.scene.plan` — :class:`Plan`, :class:`Decision`, :class:`PerturberEstimate` and
  their EXPLAIN-like text (:class:`PlanError`);
- :mod:`~spinorbit.scene.planning` — the decisions, cheapest first;
- :mod:`~spinorbit.scene.bounds` — what leaving out a torque or the back-reaction can do to the attitude;
- :mod:`~spinorbit.scene.tolerances` — the one rule from an error share to each integrator's tolerance;
- :mod:`~spinorbit.scene.integrator_choice` — Taylor or DOP853 (or the canonical elements);
- :mod:`~spinorbit.scene.sampling` — the perturbers sampled relative to the body, shared within a call;
- :mod:`~spinorbit.scene.routes` — the runners of the torque-free, one-way and coupled routes;
- :mod:`~spinorbit.scene.epochs` — output times before the epoch: the backward leg in mirrored time;
- :mod:`~spinorbit.scene.many` — several bodies (:class:`ScenePlans`, :class:`SceneResults`);
- :mod:`~spinorbit.scene.thermal` — :class:`ThermalModel`: the body feels sunlight (recoil, damping);
- :mod:`~spinorbit.scene.thermal_planning` — full or mean YORP, and why;
- :mod:`~spinorbit.scene.thermal_routes` — the runners of those two routes;
- :mod:`~spinorbit.scene.scene` — :class:`Scene` and :class:`SceneResult`.
"""

from spinorbit.scene.inputs import (
    QUANTITIES,
    EphemerisPerturber,
    FixedPerturber,
    Orbit,
    SceneError,
)
from spinorbit.scene.orbit import ApproachError
from spinorbit.scene.many import ScenePlans, SceneResults
from spinorbit.scene.plan import Decision, PerturberEstimate, Plan, PlanError
from spinorbit.scene.scene import Scene, SceneResult
from spinorbit.scene.thermal import ThermalInputError, ThermalModel, VanishingYorpWarning
from spinorbit.scene.thermal_planning import SeparatrixCrossingError

__all__ = [
    "QUANTITIES",
    "ApproachError",
    "Decision",
    "EphemerisPerturber",
    "FixedPerturber",
    "Orbit",
    "PerturberEstimate",
    "Plan",
    "PlanError",
    "Scene",
    "SceneError",
    "ScenePlans",
    "SceneResult",
    "SceneResults",
    "SeparatrixCrossingError",
    "ThermalInputError",
    "ThermalModel",
    "VanishingYorpWarning",
]
