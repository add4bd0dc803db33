"""Binary asteroids with units: two rigid figures, their state, the coupled propagation and what it shows.

- :mod:`.system` — :class:`Figure` (an ellipsoid, a sphere or a polyhedron with its inertia integrals),
  :class:`BinarySystem` (two figures and the expansion order), :class:`BinaryState` (relative orbit,
  both attitudes and spins), the DART-like impulse;
- :mod:`.run` — :func:`propagate` and :class:`BinaryRun` (drifts, the secondary's libration and
  canonical elements, the mutual period, the mean mutual orbit :class:`MutualOrbit` and the libration
  spectrum);
- :mod:`.sun` — :class:`HeliocentricOrbit`, the barycentre's orbit about the Sun for the solar tide.

The core below is :mod:`spinorbit.core.binary` (SI floats: m, kg, s, rad).
"""

from spinorbit.binary.run import BinaryRun, LibrationComponents, MutualOrbit, propagate
from spinorbit.binary.sun import HeliocentricOrbit
from spinorbit.binary.system import BinaryState, BinarySystem, Figure, momentum_impulse

__all__ = ["BinaryRun", "BinaryState", "BinarySystem", "Figure", "HeliocentricOrbit", "LibrationComponents",
           "MutualOrbit", "momentum_impulse", "propagate"]
