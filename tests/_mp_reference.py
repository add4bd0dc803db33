"""mpmath (40 digits) evaluation of the moving parts of the exact solution, for long spans.

heyoka in long double drifts by ~1e-14 per 1e4 periods (its energy random-walks at 1e-18), which
hides the double-precision phase errors this package has to keep below that. This reference takes
the time-independent parts from the package (the node-frame quaternion, g0, arg0, flip) and
recomputes everything that moves — arg(t) = arg0 + ν t, sn/cn/dn, g(t) with pn from
Π(am r, n|p) + 2jΠ(n|p), the half angles — in 40-digit arithmetic from the exact double inputs.
It validates the long-span numerics (double-double rates, period reduction); the theory itself is
validated against heyoka over the spans where heyoka is accurate.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np

from spinorbit.core.free_motion import flow_constants as tf
from spinorbit.core.elements.canonical import (
    FLIP_A,
    FLIP_B,
    FLIP_C,
    MODE_SAM,
    body_from_argument,
    flip_attitude,
    node_angles,
)
from spinorbit.core.math.rotations import quat_to_attitude


def secular_am(u, m):
    """am(u|m) for 0 ≤ m < 1, continuous in u: u = 2jK + r, am = jπ + atan2(sn r, cn r)."""
    k = mp.ellipk(m)
    j = mp.nint(u / (2 * k))
    r = u - 2 * j * k
    return j * mp.pi + mp.atan2(mp.ellipfun("sn", r, m), mp.ellipfun("cn", r, m))


def secular_pi(phi, n, m):
    """Π(φ, n|m) for any real φ, 0 ≤ m < 1, n < 1: Π(φ + jπ) = Π(φ) + 2jΠ(n|m)."""
    j = mp.nint(phi / mp.pi)
    return mp.ellippi(n, phi - j * mp.pi, m) + 2 * j * mp.ellippi(n, m)


def _qmul(a, b):
    return [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]


def exact_states(quaternion, momentum, moments, times, dps=40):
    """(q (T, 4), M (T, 3)) as floats, the moving parts evaluated with ``dps`` digits."""
    with mp.workdps(dps):
        big_a, big_b, big_c = moments
        flow, mo, mk, pk = tf.flow_constants(np.asarray(quaternion, float), np.asarray(momentum, float), *moments)
        flip = int(flow[tf.FL_FLIP])
        fx, fy, fz = flow[tf.FL_FLIP_X], flow[tf.FL_FLIP_Y], flow[tf.FL_FLIP_Z]
        mx, my, mz = (mp.mpf(float(s * v)) for s, v in zip((fx, fy, fz), momentum))
        a, b, c = 1 / mp.mpf(big_a), 1 / mp.mpf(big_b), 1 / mp.mpf(big_c)
        a_b, b_c, a_c = a - b, b - c, a - c
        g2 = mx**2 + my**2 + mz**2
        big_g = mp.sqrt(g2)
        d = (a * mx**2 + b * my**2 + c * mz**2) / g2
        sam = mo[0] == MODE_SAM
        if sam:
            nu = mp.sqrt((a - d) * g2 * b_c)
            p = a_b * (d - c) / ((a - d) * b_c)
            n = -a_b / b_c
        else:
            nu = mp.sqrt((d - c) * g2 * a_b)
            p = (a - d) * b_c / (a_b * (d - c))
            n = -(a - d) / (d - c)
        kappa = a_c * big_g / nu

        def pn(u):
            return secular_pi(secular_am(u, p), n, p)

        arg0 = mp.mpf(float(flow[tf.FL_ARG0]))
        # g at t = 0 from the initial attitude (the package's Andoyer angles, not its g constant)
        working = flip_attitude(quat_to_attitude(np.asarray(quaternion, float)), flip)
        m_working = np.array([float(mx), float(my), float(mz)])
        _, _, _, sin_l, cos_l = body_from_argument(float(arg0), mo, mk)
        g0 = mp.mpf(node_angles(working, m_working, sin_l, cos_l)[4])
        qn = [mp.mpf(float(flow[i])) for i in (tf.FL_QN_W, tf.FL_QN_X, tf.FL_QN_Y, tf.FL_QN_Z)]
        q_out, m_out = [], []
        pn0 = pn(arg0)
        for t in times:
            u = arg0 + nu * mp.mpf(float(t))
            sn, cn, dn = (mp.ellipfun(k, u, m=p) for k in ("sn", "cn", "dn"))
            first, third = (cn, dn) if sam else (dn, cn)
            x = big_g * mp.sqrt((d - c) / a_c) * first
            z = big_g * mp.sqrt((a - d) / a_c) * third
            if sam:
                y = big_g * mp.sqrt((d - c) / b_c) * sn
                ws, wc = mp.sqrt(b_c) * first, mp.sqrt(a_c) * sn
            else:
                y = big_g * mp.sqrt((a - d) / a_b) * sn
                ws, wc = mp.sqrt(a_b * (d - c)) * first, mp.sqrt(a_c * (a - d)) * sn
            g = g0 + c * big_g * mp.mpf(float(t)) + kappa * (pn(u) - pn0)
            l = mp.atan2(ws, wc)
            j_angle = mp.acos(z / big_g)
            qw = [mp.cos(j_angle / 2) * mp.cos((g + l) / 2), mp.sin(j_angle / 2) * mp.cos((g - l) / 2),
                  mp.sin(j_angle / 2) * mp.sin((g - l) / 2), mp.cos(j_angle / 2) * mp.sin((g + l) / 2)]
            q = _qmul(qn, qw)
            if flip in (FLIP_A, FLIP_B, FLIP_C):
                axis = [0, 0, 0, 0]
                axis[flip] = 1
                q = _qmul(q, axis)
            q_out.append([float(v) for v in q])
            m_out.append([float(fx * x), float(fy * y), float(fz * z)])
        return np.array(q_out), np.array(m_out)
