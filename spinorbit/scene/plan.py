"""A plan: what :meth:`spinorbit.scene.Scene.run` will do, each decision with its reason, and its text.

The records of the planner's answer, built by keyword: :class:`Decision` (one line of EXPLAIN),
:class:`PerturberEstimate` (one perturber's survey and bound), :class:`Plan` (the route, the
integrator and its first tolerance, the budget of what was left out) and ``str(plan)``, which reads
like a query planner's EXPLAIN. How the decisions are taken is :mod:`spinorbit.scene.planning`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from spinorbit.core.errors import SpinorbitError

__all__ = ["ARCSEC_PER_RAD", "Decision", "PerturberEstimate", "Plan", "PlanError"]

ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi


class PlanError(SpinorbitError, RuntimeError):
    """No plan reaches the tolerance with the routes a Scene can run (the message says which to use)."""


@dataclass(frozen=True)
class Decision:
    """One line of a plan: what was decided and why, in words and numbers."""

    topic: str
    choice: str
    reason: str


@dataclass
class PerturberEstimate:
    """Survey result for one perturber: closest distance (au) and the bound (rad) of leaving it out.

    ``bound_rad`` is the free-motion bound where it applies (:mod:`spinorbit.scene.bounds`), never
    above ``worst_attitude_rad``, the worst-attitude bound of
    :func:`~spinorbit.scene.bounds.dropped_torque_bound`.
    """

    name: str
    closest_au: float
    bound_rad: float
    kept: bool
    worst_attitude_rad: float | None = None

    @property
    def worst_or_bound_rad(self):
        """The worst-attitude bound, or ``bound_rad`` for an estimate made without it."""
        return self.bound_rad if self.worst_attitude_rad is None else self.worst_attitude_rad


@dataclass(kw_only=True)
class Plan:
    """What :meth:`spinorbit.scene.Scene.run` will do, and why (``str(plan)`` reads like EXPLAIN).

    Built by keyword only.

    Attributes
    ----------
    route : {"torque-free", "one-way", "coupled", "thermal-full", "thermal-mean"}
        Exact free motion (no integration), the one-way integration under the kept perturbers, the
        fully coupled REBOUND run (BS, :class:`~spinorbit.coupling.rigid_body.CoupledRigidBody`), or,
        for a body that feels sunlight, the full integration or the mean YORP run
        (:mod:`spinorbit.scene.thermal_planning`).
    orbit_source : {"none", "de421", "ephemeris", "rebound"}
        Where the positions come from: none needed, DE421, a user ephemeris, a REBOUND (N-body) run.
    kept, dropped : tuple of str
        Perturbers in the run and left out.
    estimates : dict
        :class:`PerturberEstimate` per perturber (empty when nothing was surveyed).
    integrator : {"quaternion", "elements", "taylor", "exact", "rebound-bs"}
    rtol : float or None
        First tolerance of the integration (:func:`spinorbit.scene.tolerances.first_tolerance`: DOP853
        rtol, Taylor tol, or BS eps_abs = eps_rel for "rebound-bs"), refined a posteriori.
    end_only : bool
        Only the final state is asked: one output time, no dense output, quantities once.
    tolerance_rad : float
    kappa : float
        Measured attitude sensitivity of the free motion (:func:`~spinorbit.scene.bounds.attitude_sensitivity`).
    dropped_bound_rad : float
        Sum of the bounds of everything left out (for the torque-free route: all perturbers).
    full : bool
        True for the reference plan of ``Scene.plan(skip=False)``: nothing skipped.
    decisions : list of Decision
    samples : SampledPerturbers or None
        For a REBOUND orbit, the survey is taken at the run's sampling tolerance and kept here, so the
        N-body run is paid once; the run uses its kept perturbers' columns.
    back_reaction_rad : float
        Bound of the figure's back-reaction on the orbits that a one-way route leaves out (0 when
        it is not left out, or when the body has no mass in the orbit model).
    back_reaction_bound_rad : float or None
        The back-reaction bound itself, also where the route does not leave it out (None: not estimated).
    """

    route: str
    orbit_source: str
    kept: tuple
    dropped: tuple
    estimates: dict
    integrator: str
    rtol: float | None
    end_only: bool
    tolerance_rad: float
    kappa: float
    dropped_bound_rad: float
    full: bool
    decisions: list = field(default_factory=list)
    samples: object = field(default=None, repr=False)
    back_reaction_rad: float = 0.0
    back_reaction_bound_rad: float | None = None
    #: For the "thermal-full" and "thermal-mean" routes: the core set-up and the mean route's estimates
    #: (:mod:`spinorbit.scene.thermal_planning`).
    thermal: object = field(default=None, repr=False)

    @property
    def integration_share_rad(self):
        """Tolerance left for integration and sampling once what was left out is paid for."""
        return self.tolerance_rad - self.dropped_bound_rad - self.back_reaction_rad

    def __str__(self):
        title = "reference plan (skip=False: nothing skipped)" if self.full else "plan"
        lines = [f"{title}: route {self.route}, orbits from {self.orbit_source}, integrator {self.integrator}"
                 + (f" (rtol {self.rtol:.1e})" if self.rtol else ""),
                 (f"  tolerance {self.tolerance_rad * ARCSEC_PER_RAD:.4g} arcsec ({self.tolerance_rad:.3e} rad); "
                  f"left out: bound {self.dropped_bound_rad * ARCSEC_PER_RAD:.3g} arcsec"
                  + (f" + back-reaction {self.back_reaction_rad * ARCSEC_PER_RAD:.3g} arcsec"
                     if self.back_reaction_rad else ""))]
        width = max(len(d.topic) for d in self.decisions) if self.decisions else 0
        for decision in self.decisions:
            lines.append(f"  -> {decision.topic.ljust(width)}  {decision.choice}")
            lines.append(f"     {' ' * width}  because {decision.reason}")
        return "\n".join(lines)
