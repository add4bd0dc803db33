"""Dense output for REBOUND's BS: a rotation at any times from the ends of BS's own (natural) steps.

REBOUND's BS has no dense output, so output times closer than its natural step (≈ 5 d for the
Moon) used to end a chunk each (``exact_finish_time``), cutting every step. Here BS takes its
natural steps and each step end is kept: (q, ω) there, and q̇ = ½ q ⊗ (0, ω) (``docs/conventions.md``).
The raw quaternion turns by ≈ 1 rad per lunar step, far too much for a polynomial; what is
interpolated is the smooth part, the rotation from a *reference* attitude (for the Moon DE421's) to
the model's,

    δq = conj(q_ref) ⊗ q,        δq̇ = ½ (δq ⊗ (0, ω) − (0, ω_ref) ⊗ δq),

which for the Moon is a few µrad varying with the monthly and longer libration periods. δq is
fitted by a Hermite polynomial through :data:`HERMITE_NODES` consecutive step ends (values and
first derivatives, degree 2·nodes − 1) around each output and put back on the reference there. The error
against the cut-step run is measured in ``tests/test_moon_dense_output.py`` and docs/performance.md.
"""

from __future__ import annotations

import numpy as np

__all__ = ["HERMITE_NODES", "hermite_interpolate", "rotation_at", "quaternion_product"]

#: Step ends per Hermite fit (values and first derivatives: degree 7). Measured on the coupled
#: Moon over a year (daily outputs, BS steps ≈ 6 d, against the cut-step run; docs/performance.md):
#: 2 nodes leave 0.013″, 3 nodes 0.002″, 4 to 6 nodes 5–6e-4″; second derivatives (ω̇ from the
#: spin equations) do not help. The floor is the reference's: DE421's libration series are
#: Chebyshev polynomials on 8-day granules, smooth within a granule only, so δq has small kinks
#: at their ends that no polynomial across them follows.
HERMITE_NODES = 4


def quaternion_product(a, b):
    """Hamilton products a ⊗ b of scalar-first quaternions along the leading axes, shape (..., 4)."""
    a0, av = a[..., :1], a[..., 1:]
    b0, bv = b[..., :1], b[..., 1:]
    return np.concatenate([a0 * b0 - np.sum(av * bv, axis=-1, keepdims=True),
                           a0 * bv + b0 * av + np.cross(av, bv)], axis=-1)


def _pure(omega):
    return np.concatenate([np.zeros(omega.shape[:-1] + (1,)), omega], axis=-1)


def hermite_interpolate(node_times, values, derivatives, times, nodes: int = HERMITE_NODES):
    """Values at ``times`` of the Hermite polynomials through ``nodes`` consecutive nodes each.

    An output in node interval [t_k, t_k+1] uses the ``nodes`` nodes centred on that interval
    (shifted inwards at the ends): the polynomial of degree (d + 1)·nodes − 1 matching the values
    and the first d derivatives there.

    Parameters
    ----------
    node_times : ndarray, shape (n,)
        Increasing (any time unit), n ≥ ``nodes``.
    values : ndarray, shape (n, m)
        The function at the nodes.
    derivatives : sequence of d ndarrays, shape (n, m)
        Its first, second, … time derivatives there (per that unit).
    times : ndarray, shape (k,)
        Inside [node_times[0], node_times[-1]].
    nodes : int
        Nodes per fit, ≥ 2.

    Returns
    -------
    ndarray, shape (k, m)

    Raises
    ------
    ValueError
        Fewer than ``nodes`` nodes, nodes < 2, or times outside the nodes' span.
    """
    node_times, times = np.asarray(node_times, dtype=float), np.asarray(times, dtype=float)
    n = node_times.size
    if nodes < 2 or n < nodes:
        raise ValueError(f"hermite_interpolate: expected at least nodes = {nodes} ≥ 2 node times, got {n}; "
                         "integrate over a longer span or use fewer nodes.")
    if times.size and (times.min() < node_times[0] or times.max() > node_times[-1]):
        raise ValueError(f"hermite_interpolate: times must lie in [{node_times[0]!r}, {node_times[-1]!r}] "
                         f"(the step ends), got [{times.min()!r}, {times.max()!r}].")
    data = [np.asarray(values, dtype=float)] + [np.asarray(d, dtype=float) for d in derivatives]
    interval = np.clip(np.searchsorted(node_times, times, side="right") - 1, 0, n - 2)
    used = np.unique(interval)
    first = np.clip(used - (nodes - 1) // 2, 0, n - nodes)  # the fit's first node, per used interval
    window = first[:, None] + np.arange(nodes)  # (u, nodes)
    t = node_times[window]
    centre, half = 0.5 * (t[:, :1] + t[:, -1:]), 0.5 * (t[:, -1:] - t[:, :1])
    x = (t - centre) / half  # nodes in [−1, 1]: a well-conditioned monomial basis
    powers = np.arange(len(data) * nodes)
    rows, rhs, factor = [], [], np.ones(powers.size)
    for order, array in enumerate(data):  # d^order/dx^order of x^p = p!/(p − order)! x^(p − order)
        rows.append(factor * x[..., None] ** np.maximum(powers - order, 0))
        rhs.append(array[window] * half[..., None] ** order)
        factor = factor * (powers - order)
    coefficients = np.linalg.solve(np.concatenate(rows, axis=1), np.concatenate(rhs, axis=1))
    which = np.searchsorted(used, interval)
    s = (times - centre[which, 0]) / half[which, 0]
    return np.einsum("kp,kpm->km", s[:, None] ** powers, coefficients[which])


def rotation_at(times, node_times, node_states, reference, nodes: int = HERMITE_NODES):
    """Unit quaternions at ``times`` from (q, ω) at BS's step ends, interpolated relative to ``reference``.

    Parameters
    ----------
    times : ndarray, shape (k,)
        Output times inside the step ends' span.
    node_times : ndarray, shape (n,)
        The step ends (increasing).
    node_states : ndarray, shape (n, 7)
        (q, ω) there: q scalar first, body → inertial; ω body axes, per time unit.
    reference : callable
        ``reference(times) -> (q_ref (·, 4), ω_ref (·, 3))``, a smooth attitude close to the body's
        (same conventions), e.g. DE421's lunar mantle; any sign of q_ref.
    nodes : int
        Step ends per Hermite fit (:data:`HERMITE_NODES`; all of them if there are fewer).

    Returns
    -------
    quaternions : ndarray, shape (k, 4)
        Unit, scalar first.
    reference_quaternions : ndarray, shape (k, 4)
        ``reference(times)[0]`` (the caller may reuse them).
    """
    q = node_states[:, :4] / np.linalg.norm(node_states[:, :4], axis=1)[:, None]
    q_ref, omega_ref = reference(node_times)
    delta = quaternion_product(q_ref * np.array([1.0, -1.0, -1.0, -1.0]), q)
    delta *= np.where(delta[:, :1] < 0.0, -1.0, 1.0)  # one sign along the run (q_ref's may flip)
    rate = 0.5 * (quaternion_product(delta, _pure(node_states[:, 4:])) - quaternion_product(_pure(omega_ref), delta))
    out_ref, _ = reference(times)
    # A span shorter than ``nodes`` steps (e.g. a few days from a body whose step has grown) has fewer.
    fitted = hermite_interpolate(node_times, delta, (rate,), times, min(nodes, node_times.size))
    result = quaternion_product(out_ref, fitted)
    return result / np.linalg.norm(result, axis=1)[:, None], out_ref
