"""mpmath references (40 digits) for the elliptic tests, fed the exact double inputs.

The parameter is built exactly from the pair (m, mc) given to spinorbit: from mc when m ≥ 0.5
(where the caller chose mc and 1 − m need not be the double m), from m otherwise.
"""

import mpmath as mp

mp.mp.dps = 40


def exact_parameter(m, mc):
    """The mpmath parameter that the double pair (m, mc) stands for."""
    return 1 - mp.mpf(mc) if m >= 0.5 else mp.mpf(m)


def _reduced(u, mm):
    """u = 2jK + r (m < 1) done in mpmath, so mpmath never sees a huge argument."""
    big_k = mp.ellipk(mm)
    j = mp.nint(mp.mpf(u) / (2 * big_k))
    return j, mp.mpf(u) - 2 * j * big_k


def sncndn(u, m, mc):
    mm = exact_parameter(m, mc)
    if mm == 1:
        x = mp.mpf(u)
        return mp.tanh(x), mp.sech(x), mp.sech(x)
    if mm > 1:  # reciprocal parameter, DLMF 22.17.2–4
        mu = 1 / mm
        v = mp.sqrt(mm) * mp.mpf(u)
        j, r = _reduced(v, mu)
        sign = -1 if j % 2 else 1
        return (
            sign * mp.ellipfun("sn", r, m=mu) / mp.sqrt(mm),
            mp.ellipfun("dn", r, m=mu),
            sign * mp.ellipfun("cn", r, m=mu),
        )
    j, r = _reduced(u, mm)
    sign = -1 if j % 2 else 1
    return (
        sign * mp.ellipfun("sn", r, m=mm),
        sign * mp.ellipfun("cn", r, m=mm),
        mp.ellipfun("dn", r, m=mm),
    )


def amplitude(u, m, mc):
    mm = exact_parameter(m, mc)
    if mm == 1:
        return mp.asin(mp.tanh(mp.mpf(u)))
    if mm > 1:
        s, c, _ = sncndn(u, m, mc)
        return mp.atan2(s, c)
    j, r = _reduced(u, mm)
    return j * mp.pi + mp.atan2(mp.ellipfun("sn", r, m=mm), mp.ellipfun("cn", r, m=mm))


def ellippi(n, phi, mm):
    """Π(n; φ | m) for exact mpmath n, m (mpmath's convention is ours)."""
    return mp.re(mp.ellippi(n, mp.mpf(phi), mm))


def pn(u, n_exact, m, mc):
    """pn(u, n|m): Π(n; am u | m) with the secular reduction for m < 1, the reciprocal-parameter
    identity pn(√m u, n/m | 1/m)/√m for m > 1, closed forms for m = 1."""
    mm = exact_parameter(m, mc)
    x = mp.mpf(u)
    if mm == 1:
        if n_exact == 1:
            return x / 2 + mp.sinh(2 * x) / 4
        f = -n_exact
        return (x + mp.sqrt(f) * mp.atan(mp.sqrt(f) * mp.tanh(x))) / (1 + f)
    if mm > 1:
        mu = 1 / mm
        v = mp.sqrt(mm) * x
        j, r = _reduced(v, mu)
        phi = mp.atan2(mp.ellipfun("sn", r, m=mu), mp.ellipfun("cn", r, m=mu))
        n_mu = n_exact / mm
        return (2 * j * mp.ellippi(n_mu, mu) + mp.ellippi(n_mu, phi, mu)) / mp.sqrt(mm)
    j, r = _reduced(u, mm)
    phi = mp.atan2(mp.ellipfun("sn", r, m=mm), mp.ellipfun("cn", r, m=mm))
    secular = 2 * j * mp.ellippi(n_exact, mm) if j != 0 else 0
    return secular + mp.ellippi(n_exact, phi, mm)


def relative_error(value, reference):
    if abs(reference) < mp.mpf(10) ** -35:  # an exact zero, up to mpmath's own 40-digit rounding
        return abs(value)
    return float(abs((mp.mpf(value) - reference) / reference))
