"""What the binary tests share: a rotation from its vector, and the mutual potential's derivatives by
five-point differences (the reference the expansion's force and torques are held to)."""

from __future__ import annotations

import numpy as np

from spinorbit.core.binary import equations as eq
from spinorbit.core.math.rotations import matrix_to_quat


def rotation(vector):
    """Rodrigues: the matrix of the rotation by |vector| about vector."""
    vector = np.asarray(vector, dtype=float)
    angle = np.linalg.norm(vector)
    k = vector / angle
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross


def five_point_derivative(f, h):
    """(−f(2h) + 8 f(h) − 8 f(−h) + f(−2h)) / 12h: truncation h⁴ f⁽⁵⁾/30."""
    return (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)


def differenced_field(y, model, attitude_a, attitude_b, h):
    """(∂U/∂R, inertial torque on A, on B) by five-point differences of U at the state y.

    R moves along each inertial axis; each body turns about each inertial axis from its attitude
    (body → inertial matrix), so the torques come out on inertial axes.
    """
    def moved(k):
        def f(x):
            z = y.copy()
            z[eq.POSITION + k] += x
            return eq.mutual_state(z, model)[0]
        return f

    def turned(offset, attitude, k):
        def f(x):
            angle = np.zeros(3)
            angle[k] = x
            z = y.copy()
            z[offset:offset + 4] = matrix_to_quat(rotation(angle) @ attitude)
            return eq.mutual_state(z, model)[0]
        return f

    grad = np.array([five_point_derivative(moved(k), h) for k in range(3)])
    torque_a = np.array([five_point_derivative(turned(eq.QUAT_A, attitude_a, k), h) for k in range(3)])
    torque_b = np.array([five_point_derivative(turned(eq.QUAT_B, attitude_b, k), h) for k in range(3)])
    return grad, torque_a, torque_b
