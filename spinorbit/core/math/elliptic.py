"""Exact elliptic-function kernels for the canonical elements of rotational motion: one import point.

Numba scalar kernels (``nopython``, callable from other compiled code). All are dimensionless; m is
the *parameter* (not the modulus k = √m) and every kernel that depends on m also takes the exact
complementary parameter ``mc = 1 − m``, formed by the caller from inertia differences
(``docs/conventions.md``). The sign of ``mc`` selects the regime: ``mc > 0`` short-axis mode
(0 ≤ m < 1), ``mc == 0`` the separatrix m = 1 (closed forms), ``mc < 0`` long-axis mode (m > 1,
through the reciprocal parameter μ = 1/m with μ_c = −mc/m). Formulas and the reasons for each
choice, with the DLMF and Carlson (1995) equations each one follows: ``docs/elliptic.md``.

The kernels live in four modules, one concept each; this module gathers their public names so that
callers (and :mod:`spinorbit.special`) have one place to import the elliptic layer from:

- :mod:`.carlson` — Carlson's symmetric integrals R_F, R_D, R_J, R_C;
- :mod:`.elliptic_periods` — the per-parameter constants (K in double-double, the split half
  period), K(m), and the reductions of u by 2K and of φ by π;
- :mod:`.jacobi` — sn, cn, dn and am;
- :mod:`.elliptic_integrals` — F, Π and Fukushima's pn (paper eq. 9).

Hot-loop API: precompute per-parameter constants once, then call the ``*_k`` kernels
------------------------------------------------------------------------------------
``mk = parameter_constants(m, mc)``
    Tuple of 10 floats (layout: the ``MK_*`` indices of :mod:`.elliptic_periods`): m, mc, the
    reduced parameter μ and μ_c actually used by the sn/cn/dn algorithm (μ = m for m ≤ 1, 1/m for
    m > 1), √μ_c, √m (1 for m ≤ 1), the quarter period K(μ) as a double-double (hi, lo), and the u-space half
    period 2K(μ)/√m split into a 24-bit head and a tail so that ``j*head`` is exact.
``nk = characteristic_constants(n, m, mc)``
    For Π(φ, n | m): (method, n, f, g, Π(n|m)) with f = −n, g = m/f and the complete integral.
``pk = pn_constants(n, m, mc)``
    For pn(u, n | m): the same layout, for the characteristic actually integrated (n/m with the
    reciprocal parameter 1/m when m > 1, DLMF 22.17.2–4). ``method == METHOD_DIVERGENT`` (n = m > 1)
    makes ``pn_k`` return NaN.

``sncndn_k(u, mk) -> (sn, cn, dn)``, ``am_k(u, mk)``, ``ellipf_k(phi, mk)``, ``ellippi_k(phi, mk, nk)``, ``pn_k(u, mk, pk)``
    The same values as the convenience kernels below, with no per-m work.

Convenience kernels (compute the constants on every call; fine outside hot loops):
``rf(x, y, z)``, ``rd(x, y, z)``, ``rj(x, y, z, p)`` (p > 0), ``rc(x, y)`` (y > 0),
``ellipk(m, mc)``, ``sncndn(u, m, mc)``, ``am(u, m, mc)``, ``ellipf(phi, m, mc)``,
``ellippi(n, phi, m, mc)``, ``pn(u, n, m, mc)``.

Domain and NaN cases (documented in the kernels): m ≥ 0; for m > 1, F and Π are real only for
|φ| ≤ arcsin(1/√m) (NaN elsewhere); at m = 1, F and Π diverge at |φ| ≥ π/2 (±inf);
pn(u, m | m) for m > 1 is non-integrable at the turning points (NaN); ``ellipk`` for m > 1 returns
the real quarter period K(1/m)/√m (the real part of the complex K(m)).
"""

from spinorbit.core.math.carlson import rc, rd, rf, rj
from spinorbit.core.math.elliptic_integrals import (
    METHOD_DIVERGENT,
    METHOD_EQUAL_TO_M,
    METHOD_GENERAL,
    METHOD_LARGE_NEGATIVE,
    NK_COMPLETE,
    NK_F,
    NK_G,
    NK_METHOD,
    NK_N,
    NK_SIZE,
    characteristic_constants,
    ellipf,
    ellipf_k,
    ellippi,
    ellippi_k,
    pi_principal,
    pn,
    pn_constants,
    pn_k,
)
from spinorbit.core.math.elliptic_periods import (
    HALF_PI,
    MK_HEAD,
    MK_K_HI,
    MK_K_LO,
    MK_M,
    MK_MC,
    MK_MU,
    MK_MUC,
    MK_SIZE,
    MK_SQRT_M,
    MK_SQRT_MUC,
    MK_TAIL,
    PI_HI,
    PI_LO,
    ellipk,
    parameter_constants,
    reduce_by_period,
)
from spinorbit.core.math.jacobi import am, am_k, sncndn, sncndn_k, sncndn_reduced

__all__ = [  # noqa: RUF022 (grouped by module, not sorted)
    # Carlson's symmetric integrals
    "rf", "rd", "rj", "rc",
    # per-parameter constants, K and the reductions
    "MK_M", "MK_MC", "MK_MU", "MK_MUC", "MK_SQRT_MUC", "MK_SQRT_M", "MK_K_HI", "MK_K_LO", "MK_HEAD",
    "MK_TAIL", "MK_SIZE", "PI_HI", "PI_LO", "HALF_PI", "parameter_constants", "ellipk", "reduce_by_period",
    # Jacobian elliptic functions
    "sncndn_k", "am_k", "sncndn", "am", "sncndn_reduced",
    # F, Π and pn
    "METHOD_GENERAL", "METHOD_LARGE_NEGATIVE", "METHOD_EQUAL_TO_M", "METHOD_DIVERGENT",
    "NK_METHOD", "NK_N", "NK_F", "NK_G", "NK_COMPLETE", "NK_SIZE", "characteristic_constants",
    "pn_constants", "pi_principal", "ellipf_k", "ellippi_k", "pn_k", "ellipf", "ellippi", "pn",
]
