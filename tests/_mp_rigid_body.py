"""A 40-digit Taylor integrator of the free rigid body in (q, ω), for finite-difference references.

Independent of the package: Euler's equations and q̇ = ½ q ⊗ (0, ω) are quadratic, so their Taylor
coefficients follow from Cauchy products, y_{k+1} = [f(y)]_k / (k + 1). Fixed steps of 0.2/|ω| with
order 30 leave a truncation error far below 1e-30 (the series converge over ≳ 1/|ω|). Central finite
differences with h = 1e-15 at 40 digits then give derivatives to ~1e-25 (truncation h² ~ 1e-30,
cancellation 1e-40/h), far below the double-precision errors under test.
"""

from __future__ import annotations

import math

import mpmath as mp

ORDER = 30
STEP_TIMES_SPIN = 0.2
DPS = 40
FD_STEP = mp.mpf("1e-15")


def _series_step(y, alphas, h):
    q0, q1, q2, q3, wx, wy, wz = ([v] for v in y)
    ax, ay, az = alphas
    half = mp.mpf(1) / 2

    def prod(u, v, k):
        return mp.fsum(u[j] * v[k - j] for j in range(k + 1))

    for k in range(ORDER):
        inv = mp.mpf(1) / (k + 1)
        dq0 = -half * (prod(q1, wx, k) + prod(q2, wy, k) + prod(q3, wz, k))
        dq1 = half * (prod(q0, wx, k) + prod(q2, wz, k) - prod(q3, wy, k))
        dq2 = half * (prod(q0, wy, k) - prod(q1, wz, k) + prod(q3, wx, k))
        dq3 = half * (prod(q0, wz, k) + prod(q1, wy, k) - prod(q2, wx, k))
        dwx, dwy, dwz = ax * prod(wy, wz, k), ay * prod(wz, wx, k), az * prod(wx, wy, k)
        for series, rate in ((q0, dq0), (q1, dq1), (q2, dq2), (q3, dq3), (wx, dwx), (wy, dwy), (wz, dwz)):
            series.append(rate * inv)
    out = []
    for series in (q0, q1, q2, q3, wx, wy, wz):
        total = mp.mpf(0)
        for coefficient in reversed(series):
            total = total * h + coefficient
        out.append(total)
    return out


def propagate(q, omega, moments, t):
    """(q(t), ω(t)) as mpf lists, at the working precision."""
    big_a, big_b, big_c = (mp.mpf(v) for v in moments)
    alphas = ((big_b - big_c) / big_a, (big_c - big_a) / big_b, (big_a - big_b) / big_c)
    y = [mp.mpf(v) for v in q] + [mp.mpf(v) for v in omega]
    spin = math.sqrt(sum(float(v) ** 2 for v in omega))
    steps = max(1, int(math.ceil(abs(float(t)) * spin / STEP_TIMES_SPIN)))
    h = mp.mpf(t) / steps
    for _ in range(steps):
        y = _series_step(y, alphas, h)
    return y[:4], y[4:]


def _qmul(a, b):
    return [a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]]


def _exp(v):
    angle = mp.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    if angle == 0:
        return [mp.mpf(1), mp.mpf(0), mp.mpf(0), mp.mpf(0)]
    s = mp.sin(angle / 2) / angle
    return [mp.cos(angle / 2), s * v[0], s * v[1], s * v[2]]


def _log(q):
    if q[0] < 0:
        q = [-x for x in q]
    s = mp.sqrt(q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
    if s == 0:
        return [mp.mpf(0)] * 3
    angle = 2 * mp.atan2(s, q[0])
    return [angle * x / s for x in q[1:]]


def stm_by_finite_differences(q, omega, moments, t):
    """(Φ, Ψ) as float nested lists: ∂(δθ, ω)(t)/∂(δθ, ω)(0) and ∂/∂(A/C, B/C) at fixed C, 40 digits."""
    with mp.workdps(DPS):
        q = [mp.mpf(v) for v in q]
        norm = mp.sqrt(sum(x * x for x in q))
        q = [x / norm for x in q]
        omega = [mp.mpf(v) for v in omega]
        big_a, big_b, big_c = (mp.mpf(v) for v in moments)
        q_ref, _ = propagate(q, omega, (big_a, big_b, big_c), t)
        q_ref_conj = [q_ref[0], -q_ref[1], -q_ref[2], -q_ref[3]]

        def local(delta, dp=(0, 0)):
            q_start = _qmul(q, _exp(delta[:3]))
            w_start = [omega[i] + delta[3 + i] for i in range(3)]
            moments_p = (big_a + dp[0] * big_c, big_b + dp[1] * big_c, big_c)
            q_end, w_end = propagate(q_start, w_start, moments_p, t)
            return _log(_qmul(q_ref_conj, q_end)) + list(w_end)

        phi = [[0.0] * 6 for _ in range(6)]
        for j in range(6):
            plus = [FD_STEP if i == j else mp.mpf(0) for i in range(6)]
            minus = [-x for x in plus]
            column = [(a - b) / (2 * FD_STEP) for a, b in zip(local(plus), local(minus))]
            for i in range(6):
                phi[i][j] = float(column[i])
        psi = [[0.0] * 2 for _ in range(6)]
        zero = [mp.mpf(0)] * 6
        for j in range(2):
            dp = (FD_STEP, 0) if j == 0 else (0, FD_STEP)
            column = [(a - b) / (2 * FD_STEP)
                      for a, b in zip(local(zero, dp), local(zero, tuple(-x for x in dp)))]
            for i in range(6):
                psi[i][j] = float(column[i])
        return phi, psi
