"""The fast core: plain floats, numpy and numba only.

Nothing under ``spinorbit.core`` imports astropy, skyfield or rebound (a test enforces this), so the
core can be called from numba-compiled loops and from REBOUND callbacks without Python overhead.

Paper-named entry points: :func:`andoyer_to_canonical` (Fukushima eq. 4) and
:func:`canonical_to_andoyer` (eqs. 7–8); the exact torque-free flow (eq. 12) of one or many states:
:func:`torque_free_states`, :func:`torque_free_states_many`.
"""

from .elements import andoyer_to_canonical, canonical_to_andoyer
from .errors import SingularElementsError, SpinorbitError
from .torque_free import torque_free_states, torque_free_states_many

__all__ = [
    "andoyer_to_canonical",
    "canonical_to_andoyer",
    "torque_free_states",
    "torque_free_states_many",
    "SingularElementsError",
    "SpinorbitError",
]
