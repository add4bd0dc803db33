"""The numerical integrators, all driving the one set of equations in :mod:`spinorbit.core.dynamics`.

- :mod:`.dop853_tableau` — the Dormand–Prince 8(5,3) coefficients;
- :mod:`.quaternion` — adaptive DOP853 in (q, ω), with dense output and landing on output times;
- :mod:`.elements` — DOP853 in Fukushima's canonical elements (free motion exact, torque as the rate);
- :mod:`.taylor` — adaptive Taylor series (Jorba–Zou recurrences) in (q, ω);
- :mod:`.splitting` — symplectic splittings: exact free flow + torque kicks;
- :mod:`.handover` — the automatic hand-over between elements and quaternions near the elements'
  singular sets.
"""
