"""All numba configuration in one place.

Every compiled kernel in the package is declared with :func:`jit`, so caching, fastmath and
error-model choices are made once, here, with their reasons.

- ``cache=True``: compiled machine code is written next to the sources and reused on the next
  import; a fresh environment pays the compile cost once.
- ``fastmath=False``: the elliptic kernels rely on IEEE semantics (no reassociation of the
  compensated sums, NaN propagation for documented NaN outputs).
- ``FUSED_MULTIPLY_ADD`` (opt-in, ``@jit(fastmath=FUSED_MULTIPLY_ADD)``): LLVM may contract a·b + c into
  one fused multiply-add (one rounding instead of two, so results change at the rounding level only;
  no reassociation, no finite-math assumptions). For the Taylor recurrences, whose time is Cauchy
  products (issue 18).
- ``INLINE`` (opt-in, ``@jit(inline=INLINE)``): numba inlines the function into every caller at its own
  IR level, before LLVM sees it. For the per-state and per-time kernels of the torque-free flow that
  take arrays: a call between separately compiled functions pays NRT reference counting for every array
  argument or slice (an atomic call each), and LLVM left those calls in place; inlined, the counts
  cancel and the array stays in registers (one time per state measurably cheaper:
  ``benchmarks/bench_torque_free.py``, issue 18).
- ``error_model="numpy"``: division by zero gives inf/NaN instead of raising inside kernels, so a
  kernel never needs a Python exception path; the public wrappers validate input before calling.
"""

import numba

# No ``nopython`` key: njit is always nopython, and numba 0.68 warns (an error under the test
# suite's ``filterwarnings = error``) when it is passed explicitly.
FUSED_MULTIPLY_ADD = frozenset({"contract"})
INLINE = "always"
JIT_OPTIONS = dict(cache=True, fastmath=False, error_model="numpy")


def jit(function=None, **overrides):
    """Compile ``function`` with the package's numba options (usable bare or with overrides)."""
    options = {**JIT_OPTIONS, **overrides}
    if isinstance(options["fastmath"], frozenset):
        options["fastmath"] = set(options["fastmath"])  # numba takes a set (the constant is frozen)
    if function is None:
        return lambda f: numba.njit(**options)(f)
    return numba.njit(**options)(function)
