"""spinorbit: rotation of rigid bodies coupled to their orbits.

The front door. Public names are listed here; everything else is an implementation detail.

- :class:`RigidBody` — principal moments and the axes that go with them.
- :class:`RotationState` — attitude and spin; mode, periods, canonical elements, exact free motion.
- :mod:`spinorbit.special` — elliptic functions and integrals for every parameter m ≥ 0.
- :mod:`spinorbit.core` — the plain-float core (paper-named maps ``andoyer_to_canonical`` and
  ``canonical_to_andoyer``).
"""

from .body import InvalidBodyError, RigidBody
from .core.errors import SingularElementsError, SpinorbitError
from .state import CanonicalElements, InvalidStateError, RotationState

__version__ = "0.1.0.dev0"

__all__ = [
    "RigidBody",
    "RotationState",
    "CanonicalElements",
    "InvalidBodyError",
    "InvalidStateError",
    "SingularElementsError",
    "SpinorbitError",
    "__version__",
]
