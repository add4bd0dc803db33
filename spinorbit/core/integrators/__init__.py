"""The numerical integrators, all driving the one set of equations in :mod:`spinorbit.core.dynamics`.

- :mod:`.dop853_tableau` — the Dormand–Prince 8(5,3) coefficients;
- :mod:`.dop853` — the one DOP853 engine (stages, error norm, dense output, step-size control, the
  adaptive and fixed-step loops) that every DOP853 propagator uses with its own right-hand side;
- :mod:`.quaternion` — adaptive DOP853 in (q, ω), with dense output and landing on output times;
- :mod:`.batch_quaternion` — the same DOP853 on many members in SIMD-friendly lanes (end states only,
  each member the scalar integrator's bits);
- :mod:`.elements` — DOP853 in Fukushima's canonical elements (free motion exact, torque as the rate);
- :mod:`.taylor_recurrences`, :mod:`.taylor` — adaptive Taylor series (Jorba–Zou recurrences) in (q, ω);
- :mod:`.splitting` — symplectic splittings: exact free flow + torque kicks;
- :mod:`.handover` — the one hand-over mechanism (alternating stretches of two integrators), and the
  automatic hand-over between elements and quaternions near the elements' singular sets.

A new DOP853 propagator is a right-hand side ``rhs(t, y, params, out)`` and, if it needs them, the
engine's three hooks (:mod:`.dop853`), not a new loop.
"""
