"""Jacobian elliptic functions and elliptic integrals for every parameter m ≥ 0.

Vectorized front ends (numpy broadcasting) of the numba kernels in
:mod:`spinorbit.core.math.elliptic`. Names and argument order follow scipy and mpmath: the parameter
m (not the modulus k), and Π(n; φ | m) with the sign convention 1 − n sin²θ (mpmath, Boost,
the paper). Unlike :mod:`scipy.special`, m > 1 and m = 1 are supported, |u| is reduced without
losing ε·|u| of phase, and the complementary parameter may be given exactly with ``mc=``.

Every function takes an optional keyword ``mc``: the complementary parameter 1 − m. Near the
separatrix m = 1 the caller usually knows mc far better than m (it is a product of inertia
differences, ``docs/conventions.md``); passing it keeps full relative accuracy in mc. Without it,
mc = 1 − m is formed here. Formulas, domain and measured accuracy: ``docs/elliptic.md``.

Scalar input gives a Python float; array input gives an ndarray of the broadcast shape.
"""

import numpy as np

from spinorbit.core.math import elliptic as _kernels
from spinorbit.core.errors import SpinorbitError
from spinorbit.core.jit import jit

__all__ = ["ArgumentRangeError", "MAX_REDUCED_ARGUMENT", "ellipj", "am", "ellipk", "ellipf", "ellippi", "pn"]

# m may arrive a few ulp below 0 from a rounded computation of a true m = 0; such values are
# treated as 0. Anything more negative is an error.
NEGATIVE_M_ROUNDING = 4.0 * np.finfo(float).eps
# m + mc must equal 1 up to the rounding of that sum (and of a caller's own subtraction).
MC_CONSISTENCY_ULPS = 4.0


#: Largest reduced argument accepted: |u| for m ≤ 1, √m |u| for m > 1 (sn(u|m) = sn(√m u|1/m)/√m), and
#: |φ| for F and Π. Below it the reduction by the half period (whose 24-bit head times j is exact for
#: |j| < 2²⁹, ``docs/elliptic.md``) loses nothing: measured ≤ 2.4e-15 against mpmath up to 1e9 for m
#: from 0.3 to 1e300; beyond 2²⁹ half periods the reduction rounds and the error grows to O(1) by
#: |u| ≈ 1e18 (1e300 gave NaN). The bound keeps a factor 2 below 2²⁹ half periods of length ≥ π.
MAX_REDUCED_ARGUMENT = 2.0**28 * np.pi


class ArgumentRangeError(SpinorbitError, ValueError):
    """An argument beyond :data:`MAX_REDUCED_ARGUMENT`, where the documented accuracy would not hold."""


# --------------------------------------------------------------------------------------------------
# Input handling
# --------------------------------------------------------------------------------------------------


def _argument_range(function_name, name, x, m):
    """Refuse |x| (times √m for m > 1 when x is u) beyond :data:`MAX_REDUCED_ARGUMENT` (NaN passes: NaN out)."""
    try:
        scale = np.sqrt(np.maximum(m, 1.0)) if name == "u" else 1.0
        reduced = np.abs(x) * scale
    except ValueError:
        return  # shapes are reported by _broadcast
    with np.errstate(invalid="ignore"):
        bad = reduced > MAX_REDUCED_ARGUMENT
    if np.any(bad):
        index = np.argmax(bad)
        value = float(np.broadcast_to(x, bad.shape).flat[index])
        parameter = float(np.broadcast_to(m, bad.shape).flat[index])
        what = f"|{name}| = {abs(value):.6g}" + (f" (√m |u| = {float(reduced.flat[index]):.6g} at m = {parameter:.6g})"
                                                  if name == "u" and parameter > 1 else "")
        raise ArgumentRangeError(
            f"{function_name}: {what} is beyond the documented domain {'|u| max(1, √m)' if name == 'u' else '|' + name + '|'} "
            f"≤ {MAX_REDUCED_ARGUMENT:.4g} (2²⁸π), where the reduction by the period is exact; beyond it the result "
            "would carry an error up to O(1). Reduce the argument by the period yourself (K is ellipk(m)) with the "
            "precision it needs."
        )


def _as_float_array(name, value):
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise TypeError(
            f"{name} must be a real number or an array of real numbers, got {type(value).__name__} "
            f"({error}); convert it with numpy.asarray(..., dtype=float) first"
        ) from None
    return array


def _broadcast(function_name, **arrays):
    """Broadcast the named arrays; a mismatch names every shape instead of numpy's generic text."""
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{k}{a.shape}" for k, a in arrays.items())
        raise ValueError(
            f"{function_name}: the shapes of the arguments do not broadcast together: {shapes}. "
            "Give arrays of equal shape, scalars, or shapes that numpy can broadcast."
        ) from None
    flat = {k: np.ascontiguousarray(np.broadcast_to(a, shape)).ravel() for k, a in arrays.items()}
    return shape, flat


def _parameter(function_name, m, mc):
    """Validate m (and mc if given); return float arrays (m, mc) with mc = 1 − m if not given."""
    m = _as_float_array("m", m)
    bad = m < -NEGATIVE_M_ROUNDING
    if np.any(bad):
        raise ValueError(
            f"{function_name}: the parameter m must be ≥ 0, got m = {float(m[bad].flat[0])!r}. "
            "m is the parameter k² (not the modulus k); for a rotating body it is never negative, "
            "so check how m was computed."
        )
    m = np.where(m < 0.0, 0.0, m)
    if mc is None:
        return m, 1.0 - m
    mc = _as_float_array("mc", mc)
    try:
        excess = np.abs((m + mc) - 1.0)
    except ValueError:
        raise ValueError(
            f"{function_name}: m{m.shape} and mc{mc.shape} do not broadcast together; "
            "mc must be given at the same points as m."
        ) from None
    bad = excess > MC_CONSISTENCY_ULPS * np.finfo(float).eps * np.maximum(1.0, np.abs(m))
    if np.any(bad):
        index = np.argmax(bad)
        m_bad = np.broadcast_to(m, bad.shape).flat[index]
        mc_bad = np.broadcast_to(mc, bad.shape).flat[index]
        raise ValueError(
            f"{function_name}: mc must be the complementary parameter 1 − m, but m = {float(m_bad)!r} and "
            f"mc = {float(mc_bad)!r} sum to {float(m_bad + mc_bad)!r}. Pass mc = 1 − m computed exactly (from "
            "inertia differences), or leave mc out."
        )
    return m, mc


def _characteristic(function_name, n, m):
    """n must keep 1 − n sin²θ > 0 on the path: reject n ≥ 1 unless n ≤ m (m ≥ 1)."""
    n = _as_float_array("n", n)
    try:
        bad = (n >= 1.0) & (n > m)
    except ValueError:
        return n  # shapes are reported by _broadcast
    if np.any(bad):
        raise ValueError(
            f"{function_name}: the characteristic n = {float(np.broadcast_to(n, bad.shape)[bad].flat[0])!r} "
            "makes 1 − n sin²θ vanish on the path of integration, so the integral diverges "
            "(Cauchy principal values are not implemented). Supported: n < 1, and 1 ≤ n ≤ m for "
            "m ≥ 1; the rotation theory needs n = −f ≤ 0 and n = m."
        )
    return n


def _result(shape, *outputs):
    if shape == ():
        values = tuple(float(o[0]) for o in outputs)
    else:
        values = tuple(o.reshape(shape) for o in outputs)
    return values if len(values) > 1 else values[0]


# --------------------------------------------------------------------------------------------------
# One compiled loop for every function: the per-m (and per-n) constants are recomputed only when the
# parameter changes, so a scalar m broadcast against many u costs one AGM.
# --------------------------------------------------------------------------------------------------

# Which kernel the loop applies (the branch is the same for every element of one call).
KIND_SNCNDN, KIND_AM, KIND_K, KIND_F, KIND_PI, KIND_PN = range(6)


@jit
def _characteristic_constants(kind, n, m, mc):
    """The constants of n for Π or pn; the other kinds take none (a tuple of the same type)."""
    if kind == KIND_PI:
        return _kernels.characteristic_constants(n, m, mc)
    if kind == KIND_PN:
        return _kernels.pn_constants(n, m, mc)
    return (0.0, 0.0, 0.0, 0.0, 0.0)


@jit
def _evaluate_loop(kind, x, n, m, mc, out0, out1, out2):
    """out0[i] (and out1, out2 for sn, cn, dn) = the kernel ``kind`` at (x[i], n[i] | m[i], mc[i])."""
    mk = _kernels.parameter_constants(m[0], mc[0])
    nk = _characteristic_constants(kind, n[0], m[0], mc[0])
    for i in range(x.size):
        if i > 0:
            same_m = m[i] == m[i - 1] and mc[i] == mc[i - 1]
            if not same_m:
                mk = _kernels.parameter_constants(m[i], mc[i])
            if not (same_m and n[i] == n[i - 1]):
                nk = _characteristic_constants(kind, n[i], m[i], mc[i])
        if kind == KIND_SNCNDN:
            out0[i], out1[i], out2[i] = _kernels.sncndn_k(x[i], mk)
        elif kind == KIND_AM:
            out0[i] = _kernels.am_k(x[i], mk)
        elif kind == KIND_K:
            out0[i] = _kernels.ellipk(m[i], mc[i])
        elif kind == KIND_F:
            out0[i] = _kernels.ellipf_k(x[i], mk)
        elif kind == KIND_PI:
            out0[i] = _kernels.ellippi_k(x[i], mk, nk)
        else:
            out0[i] = _kernels.pn_k(x[i], mk, nk)


def _evaluate(function_name, kind, arrays, n_outputs=1):
    """Broadcast the validated ``arrays`` (x, and n where the kernel has one, then m, mc), run the loop."""
    shape, flat = _broadcast(function_name, **arrays)
    m, mc = flat["m"], flat["mc"]
    x = flat.get("u", flat.get("phi", m))
    n = flat.get("n", m)  # kernels without a characteristic never read it
    outputs = [np.empty(m.size) for _ in range(n_outputs)]
    if m.size:
        out0 = outputs[0]
        _evaluate_loop(kind, x, n, m, mc, out0, outputs[1] if n_outputs > 1 else out0,
                       outputs[2] if n_outputs > 2 else out0)
    return _result(shape, *outputs)


# --------------------------------------------------------------------------------------------------
# Public functions
# --------------------------------------------------------------------------------------------------


def ellipj(u, m, *, mc=None):
    """Jacobian elliptic functions sn(u|m), cn(u|m), dn(u|m) (DLMF 22.2).

    Parameters
    ----------
    u : array_like
        Argument (dimensionless). Accurate to an absolute error of about 1e-15 up to |u| = 1e6:
        the reduction by the half period uses K in double-double (``docs/elliptic.md``).
    m : array_like
        Parameter m = k² ≥ 0. m > 1 uses the reciprocal parameter (DLMF 22.17.2–4); m = 1 gives
        tanh u, sech u, sech u.
    mc : array_like, optional
        Complementary parameter 1 − m, exact if the caller knows it (keyword only).

    Returns
    -------
    sn, cn, dn : float or ndarray
        Broadcast over the inputs; floats for scalar input.

    Raises
    ------
    ValueError
        If m < 0, mc is inconsistent with m, or the shapes do not broadcast.

    Notes
    -----
    Unlike ``scipy.special.ellipj`` (no m > 1, wrong for 1 − 1e-10 ≤ m < 1 at |u| > K,
    ε·|u| phase drift), the argument is first reduced to |r| ≤ K.
    """
    u = _as_float_array("u", u)
    m, mc = _parameter("ellipj", m, mc)
    _argument_range("ellipj", "u", u, m)
    return _evaluate("ellipj", KIND_SNCNDN, dict(u=u, m=m, mc=mc), n_outputs=3)


def am(u, m, *, mc=None):
    """Jacobi amplitude am(u|m), with sn = sin am and cn = cos am (DLMF 22.16.1).

    Parameters
    ----------
    u : array_like
        Argument (dimensionless).
    m : array_like
        Parameter m ≥ 0.
    mc : array_like, optional
        Complementary parameter 1 − m (keyword only).

    Returns
    -------
    am : float or ndarray
        Radians. For m < 1 continuous and secular (am(u + 2K) = am(u) + π, never a 2π jump);
        for m = 1 the Gudermannian gd(u); for m > 1 bounded by arcsin(1/√m) (am = atan2(sn, cn)).

    Raises
    ------
    ValueError
        If m < 0, mc is inconsistent with m, or the shapes do not broadcast.
    """
    u = _as_float_array("u", u)
    m, mc = _parameter("am", m, mc)
    _argument_range("am", "u", u, m)
    return _evaluate("am", KIND_AM, dict(u=u, m=m, mc=mc))


def ellipk(m, *, mc=None):
    """Complete elliptic integral of the first kind K(m) = F(π/2 | m) (DLMF 19.2.8).

    Parameters
    ----------
    m : array_like
        Parameter m ≥ 0.
    mc : array_like, optional
        Complementary parameter 1 − m (keyword only); K(m) ≈ ln(4/√mc) as mc → 0 is only
        accurate if mc is.

    Returns
    -------
    K : float or ndarray
        inf at m = 1. For m > 1 the real quarter period K(1/m)/√m of sn(u|m) in u, which is the
        real part of the complex K(m) (DLMF 19.7.3); scipy returns NaN there.

    Raises
    ------
    ValueError
        If m < 0, mc is inconsistent with m, or the shapes do not broadcast.
    """
    m, mc = _parameter("ellipk", m, mc)
    return _evaluate("ellipk", KIND_K, dict(m=m, mc=mc))


def ellipf(phi, m, *, mc=None):
    """Incomplete elliptic integral of the first kind F(φ|m) = ∫₀^φ dθ/√(1 − m sin²θ) (DLMF 19.2.4).

    Parameters
    ----------
    phi : array_like
        Amplitude φ in radians, any size for m < 1 (F(φ + jπ) = F(φ) + 2jK).
    m : array_like
        Parameter m ≥ 0.
    mc : array_like, optional
        Complementary parameter 1 − m (keyword only).

    Returns
    -------
    F : float or ndarray
        For m = 1: atanh(sin φ), ±inf for |φ| ≥ π/2. For m > 1: real only for
        |φ| ≤ arcsin(1/√m); NaN elsewhere.

    Raises
    ------
    ValueError
        If m < 0, mc is inconsistent with m, or the shapes do not broadcast.
    """
    phi = _as_float_array("phi", phi)
    m, mc = _parameter("ellipf", m, mc)
    _argument_range("ellipf", "phi", phi, m)
    return _evaluate("ellipf", KIND_F, dict(phi=phi, m=m, mc=mc))


def ellippi(n, phi, m, *, mc=None):
    """Incomplete integral of the third kind Π(n; φ | m) (DLMF 19.2.7, sign as in mpmath).

    Π(n; φ | m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ)).

    Parameters
    ----------
    n : array_like
        Characteristic. n < 1 for any m; 1 ≤ n ≤ m allowed for m ≥ 1. Large negative n (down to
        −1e30) keeps full accuracy (DLMF 19.7.8 with R_C; ``docs/elliptic.md``).
    phi : array_like
        Amplitude in radians; any size for m < 1 (Π(φ + jπ) = Π(φ) + 2jΠ(n|m)).
    m : array_like
        Parameter m ≥ 0.
    mc : array_like, optional
        Complementary parameter 1 − m (keyword only). With n = m, Π stays exact as m → 1.

    Returns
    -------
    Pi : float or ndarray
        For m = 1: ±inf for |φ| ≥ π/2. For m > 1: real only for |φ| ≤ arcsin(1/√m); NaN
        elsewhere.

    Raises
    ------
    ValueError
        If m < 0, mc is inconsistent with m, n ≥ 1 with n > m (divergent integral), or the
        shapes do not broadcast.
    """
    phi = _as_float_array("phi", phi)
    m, mc = _parameter("ellippi", m, mc)
    _argument_range("ellippi", "phi", phi, m)
    n = _characteristic("ellippi", n, m)
    return _evaluate("ellippi", KIND_PI, dict(n=n, phi=phi, m=m, mc=mc))


def pn(u, n, m, *, mc=None):
    """Fukushima's pn(u, n | m) = ∫₀ᵘ du′ / (1 − n sn²(u′|m)) (paper eq. 9).

    Equal to Π(n; am(u|m) | m) for m ≤ 1; for m > 1 evaluated as pn(√m u, n/m | 1/m)/√m,
    which stays secular (composing Π with the bounded m > 1 amplitude would be wrong).

    Parameters
    ----------
    u : array_like
        Argument (dimensionless), as in :func:`ellipj`.
    n : array_like
        Characteristic: n < 1 for m < 1; n ≤ 1 for m = 1; n < m for m > 1.
    m : array_like
        Parameter m ≥ 0.
    mc : array_like, optional
        Complementary parameter 1 − m (keyword only).

    Returns
    -------
    pn : float or ndarray
        NaN for n = m > 1: the integrand 1/(1 − m sn²) = 1/cn²(√m u | 1/m) is not integrable at
        the turning points, so formulas using pn(u, m | m) must be rewritten for m > 1.

    Raises
    ------
    ValueError
        If m < 0, mc is inconsistent with m, n ≥ 1 with n > m (divergent integral), or the
        shapes do not broadcast.
    """
    u = _as_float_array("u", u)
    m, mc = _parameter("pn", m, mc)
    _argument_range("pn", "u", u, m)
    n = _characteristic("pn", n, m)
    return _evaluate("pn", KIND_PN, dict(u=u, n=n, m=m, mc=mc))
