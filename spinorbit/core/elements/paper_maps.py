"""Paper-named, vectorized transformations between Andoyer variables and canonical elements.

These are the plain-float entry points that later code and outside checks call:
:func:`andoyer_to_canonical` (paper eq. 4) and :func:`canonical_to_andoyer` (eqs. 7–8). They
broadcast over arrays, validate their input, and leave the compiled work to
``spinorbit.core.elements.canonical``.
"""

import numpy as np

from spinorbit.core.elements import canonical as _canonical
from spinorbit.core.errors import SingularElementsError

_ANDOYER_NAMES = ("L", "G", "H", "l", "g", "h")
_CANONICAL_NAMES = ("S", "Z", "H", "s", "z", "h")


def _broadcast(names, values):
    arrays = [np.asarray(v, dtype=float) for v in values]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError:
        shapes = ", ".join(f"{n}{a.shape}" for n, a in zip(names, arrays))
        raise ValueError(
            f"the inputs must broadcast to one shape; got shapes {shapes}. "
            "Give scalars or arrays of one shape (or shapes numpy can broadcast)."
        ) from None
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape)).ravel() for a in arrays]
    return shape, flat


def _check_finite(names, flat):
    for name, a in zip(names, flat):
        if not np.all(np.isfinite(a)):
            index = int(np.flatnonzero(~np.isfinite(a))[0])
            raise ValueError(f"{name} must be finite; element {index} is {a[index]!r}. Remove NaN/inf inputs.")


def _check_moments(big_a, big_b, big_c):
    if np.any(big_a <= 0) or np.any(big_b <= 0) or np.any(big_c <= 0):
        raise ValueError(
            "principal moments A, B, C must be positive; got a non-positive value. "
            "Give the moments of inertia in any consistent unit."
        )
    if np.any(big_a > big_b) or np.any(big_b > big_c):
        index = int(np.flatnonzero((big_a > big_b) | (big_b > big_c))[0])
        raise ValueError(
            f"the paper's formulas need ordered moments A ≤ B ≤ C; got A={big_a[index]!r}, B={big_b[index]!r}, "
            f"C={big_c[index]!r}. Relabel the body axes (spinorbit.RigidBody does this for you)."
        )


def _validated(names, values):
    """Broadcast six variables and the moments A, B, C; check they are finite and the moments ordered."""
    names = names + ("A", "B", "C")
    shape, flat = _broadcast(names, values)
    _check_finite(names, flat)
    _check_moments(*flat[6:])
    return shape, flat


def _evaluate(kernel, flat, shape, direction):
    """Run one compiled map over the flat inputs; raise for singular states; shape the six outputs."""
    out = np.empty((6, flat[0].size))
    status = np.empty(flat[0].size, dtype=np.int64)
    kernel(*flat, out, status)
    _raise_for_status(status, shape, direction)
    return _finish(out, shape)


def _raise_for_status(status, shape, direction):
    if np.all(status == _canonical.STATUS_OK):
        return
    index = int(np.flatnonzero(status != _canonical.STATUS_OK)[0])
    where = f"element {np.unravel_index(index, shape) if shape else ()}"
    if status[index] == _canonical.STATUS_PERMANENT_ROTATION:
        raise SingularElementsError(
            f"{where} is a permanent rotation (spin exactly about the intermediate axis B, or a degenerate "
            "state of a symmetric body or sphere, or one so close to it that S and Z cannot resolve the gap): "
            "the canonical elements are infinite or carry no phase there. "
            "Propagate it with spinorbit.RotationState, which treats it as a uniform rotation."
        )
    raise SingularElementsError(
        f"{where} lies exactly on the separatrix with M_x and M_z of opposite signs; the sign of S cannot "
        f"carry that branch ({direction}). Use spinorbit.RotationState, which stores the branch explicitly."
    )


def _finish(out, shape):
    results = tuple(row.reshape(shape) for row in out)
    if shape == ():
        return tuple(float(r) for r in results)
    return results


def andoyer_to_canonical(L, G, H, l, g, h, A, B, C):
    """Canonical elements of Andoyer variables (paper eq. 4, every mode and sense).

    Parameters
    ----------
    L, G, H : array_like
        Andoyer momenta: body C-axis component, magnitude and inertial z component of the angular
        momentum (any unit, the same for all three and consistent with A, B, C).
    l, g, h : array_like
        Andoyer angles, radians.
    A, B, C : array_like
        Principal moments, A ≤ B ≤ C.

    Returns
    -------
    S, Z, H, s, z, h : float or ndarray
        Canonical elements. S = ±√(d/a) G with the sign giving the sense of rotation (+C/−C in the
        short-axis mode, +A/−A in the long-axis mode); z and h in radians, reduced to (−π, π].

    Raises
    ------
    ValueError
        Inputs that do not broadcast, are not finite, have G ≤ 0, |L| > G or |H| > G, or moments
        that are not positive and ordered.
    SingularElementsError
        Permanent rotations (no finite elements) and the two separatrix arcs that need an explicit
        branch (see ``spinorbit.core.elements.canonical``).
    """
    shape, flat = _validated(_ANDOYER_NAMES, (L, G, H, l, g, h, A, B, C))
    big_l, big_g, big_h = flat[0], flat[1], flat[2]
    if np.any(big_g <= 0):
        raise ValueError("G (the angular momentum's magnitude) must be positive; got G ≤ 0. A body at rest has no elements.")
    slack = 1e-14 * big_g
    for name, value in (("L", big_l), ("H", big_h)):
        if np.any(np.abs(value) > big_g + slack):
            raise ValueError(f"|{name}| must not exceed G (it is a component of the angular momentum); got |{name}| > G.")
    return _evaluate(_canonical.canonical_from_andoyer_many, flat, shape, "Andoyer → canonical")


def canonical_to_andoyer(S, Z, H, s, z, h, A, B, C):
    """Andoyer variables of canonical elements (paper eqs. 7–8, every mode and sense).

    Parameters
    ----------
    S, Z, H : array_like
        Canonical momenta; |S| ≤ Z, the sign of S is the sense of rotation (see
        :func:`andoyer_to_canonical`).
    s, z, h : array_like
        Canonical coordinates (s is not periodic in 2π; z, h are angles in radians).
    A, B, C : array_like
        Principal moments, A ≤ B ≤ C.

    Returns
    -------
    L, G, H, l, g, h : float or ndarray
        Andoyer variables, angles reduced to (−π, π].
    """
    shape, flat = _validated(_CANONICAL_NAMES, (S, Z, H, s, z, h, A, B, C))
    big_s, big_z, big_h = flat[0], flat[1], flat[2]
    if np.any(big_z <= 0):
        raise ValueError("Z (= G, the angular momentum's magnitude) must be positive; got Z ≤ 0.")
    slack = 1e-14 * big_z
    big_a = flat[6]
    big_c = flat[8]
    # |S| = √(d/a) G with d ∈ [c, a]: √(A/C) Z ≤ |S| ≤ Z.
    if np.any(np.abs(big_s) > big_z + slack) or np.any(np.abs(big_s) < np.sqrt(big_a / big_c) * big_z - slack):
        raise ValueError(
            "|S| must lie in [√(A/C) Z, Z] (S = ±√(d/a) G with d = 2T/G² between 1/C and 1/A); got a value "
            "outside. Check that S and Z come from the same state and the same moments."
        )
    if np.any(np.abs(big_h) > big_z + slack):
        raise ValueError("|H| must not exceed Z (H is a component of the angular momentum); got |H| > Z.")
    return _evaluate(_canonical.andoyer_from_canonical_many, flat, shape, "canonical → Andoyer")
