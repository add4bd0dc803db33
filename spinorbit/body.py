"""A rigid body: principal moments, the map from the user's body axes to A ≤ B ≤ C, mass and size.

The core works in principal axes ordered A ≤ B ≤ C (``docs/conventions.md``). Users describe bodies
in their own axes (a shape model's x, y, z); :class:`RigidBody` keeps the proper rotation that takes
user-axis components to principal-axis components, so every state can be given and returned in the
user's axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from astropy import units as u

from spinorbit.core.errors import NonFiniteError, SpinorbitError
from spinorbit.quantities import value_in

__all__ = ["RigidBody", "InvalidBodyError", "NonFiniteBodyError"]

# Relative slack for the triangle inequality A + B ≥ C: a flat plate has A + B = C exactly, and
# moments computed from a shape model carry rounding of a few ulp.
TRIANGLE_SLACK = 1e-12


class InvalidBodyError(SpinorbitError, ValueError):
    """The moments of inertia, mass or radius cannot belong to a rigid body."""


class NonFiniteBodyError(InvalidBodyError, NonFiniteError):
    """NaN or ±inf in the moments, the mass or the radius."""


def _as_moments(moments) -> tuple[np.ndarray, u.Unit]:
    if isinstance(moments, u.Quantity):
        if moments.unit.physical_type not in ("moment of inertia", "dimensionless"):
            value_in("moments", moments, u.kg * u.m**2, "[1, 2, 2.5] kg m² (or plain ratios)")  # raises, naming both
        values, unit = np.asarray(moments.value, dtype=float), moments.unit
    else:
        try:
            values, unit = np.asarray(moments, dtype=float), u.dimensionless_unscaled
        except (TypeError, ValueError):
            raise TypeError(f"moments must be three numbers or a Quantity; got {moments!r}.") from None
    if values.shape != (3,):
        raise InvalidBodyError(
            f"a rigid body needs exactly three principal moments (about its x, y, z axes); got shape {values.shape}."
        )
    if not np.all(np.isfinite(values)):
        raise NonFiniteBodyError(f"principal moments must be finite; got {values.tolist()}.")
    if np.any(values <= 0):
        raise InvalidBodyError(
            f"principal moments must be positive; got {values.tolist()}. A moment of inertia is a sum of m r² ≥ 0, "
            "and zero only for a body on a line; give three positive moments (kg m² or ratios)."
        )
    return values, unit


def _principal_permutation(values: np.ndarray) -> np.ndarray:
    """Proper rotation P (det +1) with (A, B, C) = sorted moments and v_principal = P v_user."""
    order = np.argsort(values, kind="stable")
    rows = np.eye(3)[order]
    # an odd permutation (det −1, an odd number of inversions; counted, not np.linalg.det's LU at ~5 µs
    # a body): flip one axis to keep a right-handed frame
    a, b, c = order.tolist()
    if ((a > b) + (a > c) + (b > c)) % 2:
        rows[2] *= -1.0
    return rows


@dataclass(frozen=True)
class RigidBody:
    """A rigid body described by its principal moments of inertia.

    Parameters
    ----------
    moments : array_like or Quantity, shape (3,)
        Moments about the user's body x, y, z axes (which must be principal axes), in kg m² or as
        dimensionless ratios. Any order: the body keeps the rotation to A ≤ B ≤ C.
    mass : Quantity, optional
        Mass (kg), needed for the figure's gravity field beyond degree 2 and for back-reaction.
    radius : Quantity, optional
        Reference radius (km) of the body's gravity field.
    name : str, optional
    physical : bool, optional
        Require A + B ≥ C (default True). Set False for mathematical test problems such as the
        Hairer–Lubich–Wanner free rigid body I = (2, 1, 2/3), which no mass distribution has but
        whose dynamics are well defined.

    Raises
    ------
    InvalidBodyError
        Non-finite or non-positive moments, or (with ``physical=True``) moments violating
        A + B ≥ C (no mass distribution has them).

    Notes
    -----
    f = (a − b)/(b − c) = C (B − A) / (A (C − B)) is the paper's f (eq. 5); it is 0 for A = B and
    infinite for B = C. A sphere (A = B = C) has no triaxial elements but still rotates (uniformly).

    Examples
    --------
    >>> body = RigidBody([3.0836, 3.235, 1.0])  # Toutatis-like, long axis along user z
    >>> body.principal_moments
    (1.0, 3.0836, 3.235)
    """

    moments: object
    mass: u.Quantity | None = None
    radius: u.Quantity | None = None
    name: str | None = None
    physical: bool = True
    _values: np.ndarray = field(init=False, repr=False, compare=False)
    _unit: u.Unit = field(init=False, repr=False, compare=False)
    _to_principal: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        values, unit = _as_moments(self.moments)
        big_a, big_b, big_c = np.sort(values)
        if self.physical and big_a + big_b < big_c * (1.0 - TRIANGLE_SLACK):
            raise InvalidBodyError(
                f"moments {values.tolist()} violate the triangle inequality A + B ≥ C "
                f"({float(big_a)!r} + {float(big_b)!r} < {float(big_c)!r}); no mass distribution has them. Check the "
                "values and their axes, or pass physical=False for a mathematical test problem."
            )
        for name, value, expected_unit, example in (("mass", self.mass, u.kg, "6e10 * u.kg"),
                                                    ("radius", self.radius, u.km, "0.2 * u.km")):
            if value is None:
                continue
            try:
                magnitude = value_in(name, value, expected_unit, example, shape=())
            except ValueError as error:  # NaN, inf or an array
                raise (NonFiniteBodyError if "finite" in str(error) else InvalidBodyError)(str(error)) from None
            if not magnitude > 0:
                raise InvalidBodyError(f"{name} must be positive, such as {example}; got {value!s}.")
        values = values.copy()  # the body's own: np.asarray may have returned the caller's array
        to_principal = _principal_permutation(values)
        values.flags.writeable = False  # shared with the states built on this body: never changed
        to_principal.flags.writeable = False
        object.__setattr__(self, "_values", values)
        object.__setattr__(self, "_unit", unit)
        object.__setattr__(self, "_to_principal", to_principal)

    @property
    def principal_moments(self) -> tuple[float, float, float]:
        """(A, B, C), A ≤ B ≤ C, as plain floats in :attr:`moment_unit`."""
        big_a, big_b, big_c = np.sort(self._values)
        return float(big_a), float(big_b), float(big_c)

    @property
    def moment_values(self) -> np.ndarray:
        """The moments about the user's body x, y, z, as plain floats in :attr:`moment_unit` (read-only)."""
        return self._values

    @property
    def moment_unit(self) -> u.Unit:
        """Unit of the moments (dimensionless when given as ratios)."""
        return self._unit

    @property
    def to_principal(self) -> np.ndarray:
        """Proper rotation P: principal-axis components = P @ user-axis components (read-only)."""
        return self._to_principal

    @property
    def f(self) -> float:
        """The paper's f = (a − b)/(b − c) = C (B − A)/(A (C − B)) (eq. 5); inf for B = C."""
        big_a, big_b, big_c = self.principal_moments
        if big_c == big_b:
            return math.inf
        return big_c * (big_b - big_a) / (big_a * (big_c - big_b))

    @property
    def is_sphere(self) -> bool:
        big_a, _, big_c = self.principal_moments
        return big_a == big_c

    @property
    def is_axisymmetric(self) -> bool:
        big_a, big_b, big_c = self.principal_moments
        return big_a == big_b or big_b == big_c
