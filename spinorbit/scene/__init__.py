"""A run described declaratively, and the planner that decides how to run it.

:class:`Scene` says what a run needs — body, perturbers, orbit, output times, tolerance; its
``plan()`` decides cheapest-first and says why, ``run()`` does it (``docs/scenes.md``).
"""

from spinorbit.scene.scene import (
    QUANTITIES,
    EphemerisPerturber,
    FixedPerturber,
    Orbit,
    PlanError,
    Scene,
    SceneError,
    SceneResult,
)

__all__ = ["QUANTITIES", "EphemerisPerturber", "FixedPerturber", "Orbit", "PlanError", "Scene", "SceneError",
           "SceneResult"]


def __getattr__(name):
    from spinorbit import old_paths

    return old_paths.forward_attribute(__name__, name)
