"""Which integrator the one-way route runs, and why: the Taylor method while the knots are few, else DOP853.

The Taylor method (:mod:`spinorbit.core.integrators.taylor`) is the fastest integrator with smooth
perturbers, but a Taylor step ends at every knot of a Hermite-sampled perturber, while the quaternion
DOP853 steps across them. :func:`choose_integrator` counts both (:func:`taylor_steps`) and takes
Taylor while the knots are at most :data:`TAYLOR_KNOT_SHARE` × the rotation's own steps; the
canonical elements run only when asked for and the state is away from their singular sets
(:func:`elements_choice`). ``docs/scenes.md`` gives the measurements behind the rule.
"""

from __future__ import annotations

import math

import numpy as np

from spinorbit.scene.tolerances import (
    SURVEY_TOLERANCE,
    first_tolerance,
    survey_tolerance,
)

__all__ = ["SAMPLE_REFINEMENT", "SINGULAR_MARGIN", "TAYLOR_KNOT_SHARE", "TAYLOR_PROBE_ROTATIONS",
           "choose_integrator", "elements_choice", "taylor_steps"]

#: Near the singular sets of the canonical elements the planner refuses that integrator: 1 − m (or
#: 1 − μ) and sin J below this many times the element integrator's own stop thresholds.
SINGULAR_MARGIN = 100.0
#: Taylor while the sampled perturbers' knots inside the span are at most this many times the steps the
#: rotation needs: just below where the two integrators alone break even (bench_scene_skips,
#: docs/performance.md: between the moonlet rows of 1 and 2.5 knots per rotation step).
TAYLOR_KNOT_SHARE = 2.0
#: The rotation steps are counted by a Taylor run of the free motion over at most this many rotations
#: (2π/|ω|), scaled to the span: a few hundred steps.
TAYLOR_PROBE_ROTATIONS = 20.0
#: Sample times of the run per time of the survey's a priori grid (coupling.sampling.a_priori_grid): the
#: run's refinement passes add 1.0–1.9× (bench_scene_skips, docs/scenes.md).
SAMPLE_REFINEMENT = 1.4


def choose_integrator(scene, skip, source, kept, share):
    """The one-way route's integrator and why: (name, reason).

    "auto" takes the Taylor method (:func:`spinorbit.core.integrators.taylor.integrate_taylor`) when
    the sampled perturbers' knots inside the span are at most :data:`TAYLOR_KNOT_SHARE` × the steps
    the rotation needs, else the quaternion DOP853. The one-way model's figure is the principal
    moments alone (degree-2 torques, ``propagate_one_way``), for which the Taylor recurrences exist
    (they have no degree-3/4 terms). Why knots: a Taylor step ends at every sample time (the
    Hermite interpolant is not smooth across it), so the Taylor run takes about rotation steps +
    knots steps, while DOP853 steps across them (:func:`taylor_steps`: both counts, estimated).
    The reference plan (``skip=False``) runs the quaternion DOP853, the integrator the other
    routes are checked against, unless another one is asked for.
    """
    measured = ("the Taylor method is the fastest integrator of work-precision scene (a) (docs/performance.md), "
                "but a Taylor step ends at every sample time of a sampled perturber")
    if scene.integrator == "elements":
        return elements_choice(scene)
    if scene.integrator == "quaternion":
        return "quaternion", "asked for (non-singular everywhere)"
    if scene.integrator == "auto" and not skip:
        return "quaternion", ("skip=False (reference run): the quaternion DOP853, non-singular everywhere and the "
                              "integrator the planned routes are checked against")
    tol = first_tolerance("taylor", share)
    steps, knots, probed = taylor_steps(scene, source, kept, skip, tol)
    counts = (f"the rotation needs ≈ {steps:.0f} Taylor steps (the free motion at tol {tol:.1e} over "
              f"{probed:.3g} d of the span's {scene.span_days:.4g} d, scaled) and the sampled perturbers add "
              f"≈ {knots:.0f} knots")
    if scene.integrator == "taylor":
        return "taylor", f"asked for; {counts}"
    limit = TAYLOR_KNOT_SHARE * steps
    rule = (f"(Taylor while knots ≤ {TAYLOR_KNOT_SHARE:g} × the rotation steps = {limit:.0f}: where the two "
            "integrators alone break even at their first tolerances, bench_scene_skips in docs/performance.md)")
    if knots <= limit:
        return "taylor", f"{counts} {rule}; {measured}, and here there are few"
    return "quaternion", f"{counts} {rule}; {measured}, and here they dominate: the quaternion DOP853 steps across them"


def taylor_steps(scene, source, kept, skip, tol):
    """(rotation steps, knots inside the span, probed days) for the Taylor rule.

    Rotation steps: :func:`~spinorbit.core.integrators.taylor.integrate_taylor` on the free motion
    over at most :data:`TAYLOR_PROBE_ROTATIONS` × 2π/|ω|, scaled to the span (the torques are weak
    against the rotation, so they hardly change the steps, ``docs/scenes.md``). Knots: the sample times the run will
    have strictly inside (epoch, last output): counted for samples the plan keeps for the run,
    otherwise the a priori grid (:func:`spinorbit.coupling.sampling.a_priori_grid`) of the survey's
    states at the run's sample tolerance × :data:`SAMPLE_REFINEMENT`. Perturbers sampled on
    separate grids (DE421/REBOUND bodies and user ephemerides) add their counts.
    """
    from spinorbit.core.dynamics.equations import make_model
    from spinorbit.core.integrators.taylor import integrate_taylor

    free = make_model(scene.state.body.principal_moments)  # the figure the one-way run uses
    y0 = scene.state.core_state()
    spin = float(np.linalg.norm(y0[4:]))
    probed = scene.span_days if spin == 0.0 else min(scene.span_days, TAYLOR_PROBE_ROTATIONS * 2 * math.pi / spin)
    _, stats = integrate_taylor(y0, scene.epoch_day, [scene.epoch_day + probed], free, tol=tol, return_stats=True)
    steps = stats["steps"] * scene.span_days / probed
    named = [n for n in kept if n in scene.named]
    moving = [p.name for p in scene.moving if p.name in kept]
    groups = []
    if named:
        exact = scene.keeps_survey(source, skip)  # then the run samples are the survey's (plan.samples)
        groups.append((scene.sample_perturbers(source, named, survey_tolerance(exact, scene.sample_tolerance)), exact))
    if moving:
        groups.append((scene.sample_perturbers("user", moving, SURVEY_TOLERANCE), False))
    knots = 0.0
    t0, t1 = scene.epoch_day, scene.output_days[-1]
    for samples, exact in groups:
        days = samples.days if exact else scene.grid_of(samples, scene.sample_tolerance)  # once per shared sampling
        inside = float(np.count_nonzero((days > t0) & (days < t1)))
        knots += inside if exact else SAMPLE_REFINEMENT * inside
    return steps, knots, probed


def elements_choice(scene):
    """The canonical elements when asked for and the state is away from their singular sets.

    The distances are the integrator's own (:func:`~spinorbit.core.integrators.handover.singularity_distances_of_state`),
    each against :data:`SINGULAR_MARGIN` × its stop threshold, except the equal-moment plane of a
    symmetric body (sin P), held to the hand-over's resume margin: its threshold is 1e-2, so the
    100× margin would refuse every symmetric body.
    """
    from spinorbit.core.integrators.elements import (
        MIN_SEPARATRIX_DISTANCE,
        MIN_SIN_J,
        MIN_SIN_J_A,
        MIN_SIN_P,
    )
    from spinorbit.core.integrators.handover import (
        RESUME_MARGIN,
        singularity_distances_of_state,
    )

    moments = np.array(scene.state.body.principal_moments)
    separatrix, sin_j, _, sin_j_a, sin_p = singularity_distances_of_state(scene.state.core_state(), moments)
    limits = {"1 - m": (abs(separatrix), SINGULAR_MARGIN * MIN_SEPARATRIX_DISTANCE),
              "sin J": (sin_j, SINGULAR_MARGIN * MIN_SIN_J),
              "sin J_A": (sin_j_a, SINGULAR_MARGIN * MIN_SIN_J_A),
              "sin P": (sin_p, RESUME_MARGIN * MIN_SIN_P)}
    numbers = ", ".join(f"{name} = {value:.2g}" for name, (value, _) in limits.items())
    near = [f"{name} < {limit:g}" for name, (value, limit) in limits.items() if not value >= limit]
    if near:
        return "quaternion", (f"elements were asked but the state is near their singular sets ({numbers}; "
                              f"{', '.join(near)}): the non-singular quaternion integrator is used")
    return "elements", f"asked for; the state is away from the singular sets ({numbers})"
