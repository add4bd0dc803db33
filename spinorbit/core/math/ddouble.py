"""Double-double arithmetic: error-free transformations and (hi, lo) pairs (Dekker 1971; Knuth 4.2.2).

One copy for the package: the elliptic kernels (K as a double-double) and the long-span torque-free
flow (rates, periods and secular advances) both import from here. A double-double x = hi + lo with
|lo| ≤ ulp(hi)/2 carries about 106 bits (relative error ≈ 1e-32). The exact product's error term
comes from one fused multiply-add (``llvm.fma``: the CPU's instruction, or the C library's correctly
rounded ``fma`` where the CPU has none). The error term is exact, so it is the number Veltkamp's split
gave and the results are the same on every IEEE-754 machine (checked in exact rational arithmetic,
``tests/test_ddouble.py``), at 2 operations instead of 17.
"""

import math

import numpy as np
from numba.core import types
from numba.extending import intrinsic

from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.lanes import fma_typing, select

# Veltkamp split factor 2^27 + 1: splits a double into two 26-bit halves (Dekker's exact product).
SPLIT_26 = 134217729.0

# 2π as a double-double (2·fl(π), 2·(π − fl(π))), for reducing secular angles.
TWO_PI_HI = 2.0 * math.pi
TWO_PI_LO = 2.0 * 1.2246467991473532e-16


@jit
def two_sum(a, b):
    """a + b = s + e exactly (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@jit
def quick_two_sum(a, b):
    """a + b = s + e exactly, assuming |a| ≥ |b| (Dekker)."""
    s = a + b
    return s, b - (s - a)


@jit
def split(a, factor):
    """Veltkamp split: a = head + tail with head of (53 − log2(factor − 1)) significant bits."""
    t = factor * a
    head = t - (t - a)
    return head, a - head


@intrinsic
def fma(typingctx, a, b, c):
    """a·b + c rounded once (IEEE 754 fusedMultiplyAdd) for three float64, inside compiled code
    (lane by lane where an operand is :mod:`.lanes`' ``Lanes``)."""
    vector = fma_typing(a, b, c)
    if vector is not None:
        return vector
    if not all(isinstance(t, types.Float) for t in (a, b, c)):
        return None

    def codegen(context, builder, signature, args):
        return builder.fma(*(context.cast(builder, v, t, types.float64)
                             for v, t in zip(args, signature.args)))

    return types.float64(a, b, c), codegen


@jit
def two_prod(a, b):
    """a * b = p + e exactly: e = fma(a, b, −p) (the rounding error of the product is a double).

    The same (p, e) as Dekker's product with Veltkamp's split (:func:`split`) wherever that does not
    overflow (|a|, |b| < 1e300), in 2 operations instead of 17: e is unique, p + e = a·b exactly.
    """
    p = a * b
    return p, fma(a, b, -p)


@jit
def dd_add(ah, al, bh, bl):
    """(ah + al) + (bh + bl) as a double-double."""
    s, e = two_sum(ah, bh)
    return quick_two_sum(s, e + (al + bl))


@jit
def dd_mul(ah, al, bh, bl):
    """(ah + al) · (bh + bl) as a double-double."""
    p, e = two_prod(ah, bh)
    return quick_two_sum(p, e + (ah * bl + al * bh))


@jit
def dd_div(ah, al, bh, bl):
    """(ah + al) / (bh + bl) as a double-double (one Newton correction of the double quotient)."""
    q1 = ah / bh
    ph, pl = dd_mul(bh, bl, q1, 0.0)
    rh, rl = dd_add(ah, al, -ph, -pl)
    return quick_two_sum(q1, rh / bh)


@jit
def dd_sqrt(ah, al):
    """√(ah + al) as a double-double (one Newton correction of the double root); 0 for 0."""
    h = math.sqrt(ah)
    if h == 0.0:
        return 0.0, 0.0
    return _corrected_root(ah, al, h)


@jit
def dd_sqrt_lanes(ah, al):
    """:func:`dd_sqrt` in every lane of ``Lanes`` (:mod:`.lanes`), bit for bit."""
    h = math.sqrt(ah)
    hi, lo = _corrected_root(ah, al, h)
    zero = h == 0.0
    return select(zero, 0.0, hi), select(zero, 0.0, lo)


@jit(inline=INLINE)
def _corrected_root(ah, al, h):
    """h = √ah rounded, plus its Newton correction from the exact residual, as a double-double."""
    p, e = two_prod(h, h)
    return quick_two_sum(h, (((ah - p) - e) + al) / (2.0 * h))


@jit
def parity(j):
    """|j| mod 2 (0.0 or 1.0) of an integer-valued float j, as ``abs(j) % 2.0`` gives it (NaN for
    NaN and ±inf) without the C library's fmod, which numba calls instead of inlining (≈ 5 ns of
    each torque-free evaluation). Exact for |j| < 2^53: each operation is."""
    a = abs(j)
    return a - 2.0 * np.floor(0.5 * a)  # np.floor stays a double (numba's math.floor is an int)


@jit
def dd_remainder_dd(xh, xl, ph, pl):
    """(j, r_hi, r_lo) with j = rint(x / p) and r = x − j·p kept as a double-double."""
    j = np.rint(xh / ph)
    qh, ql = two_prod(j, ph)
    ql += j * pl
    rh, rl = dd_add(xh, xl, -qh, -ql)
    return j, rh, rl


@jit
def dd_remainder(xh, xl, ph, pl):
    """(j, r) with j = rint(x / p) and r = x − j·p as a double (|r| ≤ p/2 plus rounding).

    x and the period p are double-doubles; j·p is formed exactly from two products, so r keeps an
    absolute error ≈ ε·|r| + |j|·|p|·1e-32: a phase carried this way does not drift with |x|.
    """
    j = np.rint(xh / ph)
    qh, ql = two_prod(j, ph)
    ql += j * pl
    rh, rl = dd_add(xh, xl, -qh, -ql)
    return j, rh + rl


@jit
def dd_scale(xh, xl, t):
    """(xh + xl) · t for a double t, as a double-double (a rate times a time, the phase of a flow)."""
    ph, pl = two_prod(xh, t)
    return dd_add(ph, pl, xl * t, 0.0)


@jit
def dd_difference_ratio(big_x, big_y):
    """(Y − X)/(X Y) = 1/X − 1/Y as a double-double, exact inputs X, Y (a − b = (B − A)/(AB))."""
    dh, dl = two_sum(big_y, -big_x)
    ph, pl = two_prod(big_x, big_y)
    return dd_div(dh, dl, ph, pl)
