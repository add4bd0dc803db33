"""Two rigid figures with units, their state, and an impulse on the secondary.

Units in, SI floats to :mod:`spinorbit.core.binary` (m, kg, s, rad), units back out. G is astropy's
``constants.G`` (CODATA 2018, 6.67430e-11 m³ kg⁻¹ s⁻²). Frames and the state layout:
``docs/conventions.md``, "The binary".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import constants
from astropy import units as u

from spinorbit.core.binary import equations as core
from spinorbit.core.binary.errors import UnsupportedOrderError
from spinorbit.core.binary.inertia_integrals import (
    INTEGRALS_SIZE,
    ellipsoid_integrals,
    inertia_tensor,
    polyhedron_integrals,
)
from spinorbit.core.binary.monomials import DEGREE_START, EXPONENTS, MAX_ORDER
from spinorbit.core.binary.propagate import check_order, check_separation
from spinorbit.core.math.rotations import quat_to_matrix
from spinorbit.quantities import finite_result, value_in

#: Newton's constant in SI (astropy, CODATA 2018).
G_SI = constants.G.si.value


@dataclass(frozen=True)
class Figure:
    """A rigid body: its inertia integrals on its own axes (SI), circumscribing radius and supported order.

    Build it with :meth:`ellipsoid`, :meth:`sphere`, :meth:`from_shape` (a constant-density polyhedron)
    or :meth:`from_inertia` (mass and inertia tensor only). ``supported_order`` is the highest expansion
    order its integrals are known to: MAX_ORDER for ellipsoids, spheres and polyhedra (exact), 2 for a
    body known by its inertia tensor alone. ``semi_axes_m`` is set for ellipsoids only;
    ``to_principal`` (polyhedra) turns the shape's axes onto the figure's body axes.
    """

    name: str
    integrals: np.ndarray
    circumscribing_radius_m: float
    semi_axes_m: tuple | None
    supported_order: int = MAX_ORDER
    to_principal: np.ndarray | None = None

    @classmethod
    @finite_result("Figure.ellipsoid", "its mass or inertia integrals (up to ρ a⁷) overflow double precision")
    def ellipsoid(cls, name, semi_axes, density):
        """A homogeneous ellipsoid with semi-axes (a, b, c) along its x, y, z axes.

        Raises ValueError for non-positive or unsorted semi-axes or density.

        Parameters
        ----------
        semi_axes : Quantity (3,), length
            a ≥ b ≥ c, so that the principal moments on x, y, z are A ≤ B ≤ C (``docs/conventions.md``).
        density : Quantity, mass density
        """
        axes = value_in("semi_axes", semi_axes, u.m, "[103.16, 79.35, 66.13] * u.m", shape=(3,))
        rho = value_in("density", density, u.kg / u.m ** 3, "2.2031 * u.g / u.cm**3", shape=())
        if np.any(axes <= 0) or rho <= 0:
            raise ValueError(f"{name}: expected positive semi-axes and density, got semi_axes = {axes.tolist()} m, "
                             f"density = {rho} kg/m³; a figure needs a volume and a mass.")
        if not axes[0] >= axes[1] >= axes[2]:
            raise ValueError(f"{name}: expected semi-axes a ≥ b ≥ c along x, y, z (the long axis on x, so that "
                             f"A ≤ B ≤ C), got {axes.tolist()} m; sort them and turn the attitude to match.")
        mass = rho * 4.0 / 3.0 * math.pi * float(np.prod(axes))
        return cls(name, ellipsoid_integrals(mass, axes), float(axes.max()), tuple(float(a) for a in axes))

    @classmethod
    @finite_result("Figure.sphere", "its mass or inertia integrals (up to ρ r⁷) overflow double precision")
    def sphere(cls, name, radius, density):
        """A homogeneous sphere (its field is a point mass's, at every order)."""
        r = value_in("radius", radius, u.m, "390 * u.m", shape=())
        return cls.ellipsoid(name, [r, r, r] * u.m, density)

    @classmethod
    @finite_result("Figure.from_shape")
    def from_shape(cls, name, shape, density=None, mass=None):
        """A constant-density polyhedron (a :class:`spinorbit.shape.Shape`) on its principal axes.

        The figure's body axes are the shape's principal axes about its centre of mass, A ≤ B ≤ C on
        x, y, z (``to_principal`` takes the shape's axes there: x_body = to_principal @ (x_shape − centre));
        its integrals to order 4 are exact to rounding (:func:`~spinorbit.core.binary.inertia_integrals.
        polyhedron_integrals`), its circumscribing radius the farthest vertex from the centre of mass.

        Parameters
        ----------
        shape : spinorbit.shape.Shape
        density : Quantity, mass density, optional
        mass : Quantity, mass, optional
            Exactly one of density and mass.
        """
        if (density is None) == (mass is None):
            raise ValueError(f"{name}: give exactly one of density (such as 2200 * u.kg / u.m**3) or mass (such as "
                             f"4.3e9 * u.kg); got density={density!r}, mass={mass!r}.")
        vertices_m = shape.vertices.to_value(u.m)
        unit_integrals, _, rotation, principal_vertices = polyhedron_integrals(vertices_m, shape.faces, 1.0)
        if density is not None:
            rho = value_in("density", density, u.kg / u.m ** 3, "2200 * u.kg / u.m**3", shape=())
        else:
            rho = value_in("mass", mass, u.kg, "4.3e9 * u.kg", shape=()) / unit_integrals[0]
        if not rho > 0:
            raise ValueError(f"{name}: expected a positive density or mass, got a density of {rho!r} kg/m³.")
        radius = float(np.linalg.norm(principal_vertices, axis=1).max())
        return cls(name, rho * unit_integrals, radius, None, MAX_ORDER, rotation)

    @classmethod
    @finite_result("Figure.from_inertia")
    def from_inertia(cls, name, mass, inertia, circumscribing_radius):
        """A body known by its mass and inertia tensor only: its figure supports expansion order 2.

        The second moments are T₂ = ½ tr(I) E − I; the degree-3 and 4 integrals are unknown, so a system
        of a higher order refuses it (:class:`~spinorbit.core.binary.errors.UnsupportedOrderError`).

        Parameters
        ----------
        mass : Quantity, mass
        inertia : Quantity (3, 3) or (3,), kg m²
            Inertia tensor about the centre of mass on the body axes (or its diagonal, principal moments).
        circumscribing_radius : Quantity, length
            Radius of a sphere about the centre of mass that contains the body (for the contact distance).
        """
        m = value_in("mass", mass, u.kg, "4.3e9 * u.kg", shape=())
        tensor = np.asarray(value_in("inertia", inertia, u.kg * u.m ** 2, "[2.1e12, 3.2e12, 3.9e12] * u.kg * u.m**2"))
        tensor = np.diag(tensor) if tensor.shape == (3,) else tensor
        radius = value_in("circumscribing_radius", circumscribing_radius, u.m, "103 * u.m", shape=())
        if tensor.shape != (3, 3) or not np.allclose(tensor, tensor.T, rtol=1e-12, atol=0.0):
            raise ValueError(f"{name}: expected a symmetric (3, 3) inertia tensor or 3 principal moments, got "
                             f"{tensor.tolist()} kg m².")
        moments = np.linalg.eigvalsh(tensor)
        if not m > 0 or not radius > 0 or not moments[0] > 0 or moments[0] + moments[1] < moments[2] * (1 - 1e-12):
            raise ValueError(f"{name}: expected a positive mass and radius and a physical inertia tensor (positive "
                             f"principal moments obeying A + B ≥ C), got mass {m} kg, radius {radius} m, principal "
                             f"moments {moments.tolist()} kg m².")
        second = 0.5 * np.trace(tensor) * np.eye(3) - tensor
        integrals = np.zeros(INTEGRALS_SIZE)
        integrals[0] = m
        for index in range(DEGREE_START[2], DEGREE_START[3]):
            # T^α for |α| = 2 is the second moment ∫ x_i x_j dm of the two axes the multi-index names.
            first, second_axis = np.repeat(np.arange(3), EXPONENTS[index])
            integrals[index] = second[first, second_axis]
        return cls(name, integrals, float(radius), None, 2, None)

    @property
    def mass(self):
        """Mass (kg)."""
        return self.integrals[0] * u.kg

    @property
    def moments(self):
        """Principal moments (A, B, C) on the body x, y, z axes (kg m²)."""
        return np.diag(inertia_tensor(self.integrals)) * u.kg * u.m ** 2


@dataclass(frozen=True)
class BinarySystem:
    """A primary A and a secondary B and the order of their mutual-potential expansion (0 … 4)."""

    primary: Figure
    secondary: Figure
    order: int = 2

    def __post_init__(self):
        check_order(self.order)
        for role, figure in (("primary", self.primary), ("secondary", self.secondary)):
            if self.order > figure.supported_order:
                raise UnsupportedOrderError(
                    f"order {self.order}: the {role} {figure.name!r} has inertia integrals to order "
                    f"{figure.supported_order} only (a body known by its inertia tensor has no degree-3 or 4 "
                    f"integrals); use order ≤ {figure.supported_order}, or build it from its shape "
                    "(Figure.from_shape, Figure.ellipsoid).")

    @property
    def contact_distance(self):
        """Sum of the circumscribing radii: closer than this, the series diverges (m)."""
        return (self.primary.circumscribing_radius_m + self.secondary.circumscribing_radius_m) * u.m

    def model(self):
        """The core's flat model array (SI)."""
        return core.make_binary_model(G_SI, self.primary.integrals, self.secondary.integrals, self.order,
                                      self.contact_distance.to_value(u.m))

    @finite_result("BinarySystem.circular_speed")
    def circular_speed(self, separation):
        """Relative speed of the circular orbit at ``separation`` with B's long axis towards A (Quantity m/s).

        From the radial force of the truncated mutual potential itself, v² = |∂U/∂R| R / ν, so the orbit is
        circular for the model that is integrated (not only for point masses).
        """
        r = value_in("separation", separation, u.m, "1200 * u.m", shape=())
        check_separation(r, self.contact_distance.to_value(u.m), "the separation asked for")
        y = np.zeros(core.BINARY_STATE_SIZE)
        y[core.POSITION] = r
        y[core.QUAT_A] = y[core.QUAT_B] = 1.0
        _, grad, _, _, _ = core.mutual_state(y, self.model())
        reduced = 1.0 / (1.0 / self.primary.integrals[0] + 1.0 / self.secondary.integrals[0])
        return math.sqrt(-grad[0] * r / reduced) * u.m / u.s


def _unit_quaternion(name, q):
    q = np.asarray(q, dtype=float)
    if q.shape != (4,) or not np.all(np.isfinite(q)) or not np.any(q):
        raise ValueError(f"{name}: expected a non-zero scalar-first quaternion (w, x, y, z), got {q.tolist()}; "
                         "use (1, 0, 0, 0) for the body axes on the inertial axes.")
    return q / np.linalg.norm(q)


@dataclass(frozen=True)
class BinaryState:
    """Relative orbit and both rotations at one instant (inertial axes; body-frame spins).

    ``separation`` and ``velocity`` are B's centre of mass relative to A's; quaternions are scalar first
    and take each body's axes to the inertial axes; spins are on each body's own axes.
    """

    system: BinarySystem
    separation: u.Quantity
    velocity: u.Quantity
    primary_quaternion: tuple
    primary_spin: u.Quantity
    secondary_quaternion: tuple
    secondary_spin: u.Quantity

    def __post_init__(self):
        # the units now, not at the first propagation: a bare number is refused where it was given
        for name, value, unit, example in (("separation", self.separation, u.m, "[1200, 0, 0] * u.m"),
                                           ("velocity", self.velocity, u.m / u.s, "[0, 0.1757, 0] * u.m / u.s"),
                                           ("primary_spin", self.primary_spin, u.rad / u.s, "[0, 0, 7.7e-4] * u.rad / u.s"),
                                           ("secondary_spin", self.secondary_spin, u.rad / u.s,
                                            "[0, 0, 1.46e-4] * u.rad / u.s")):
            value_in(name, value, unit, example, shape=(3,), finite=False)

    @classmethod
    def synchronous(cls, system, separation, primary_spin, speed=None, libration=0 * u.rad):
        """B on an orbit in the inertial x-y plane at +x, its long axis (x) along the line to A, spinning at the
        orbit's mean rate about its z axis; A spinning about its z axis.

        Parameters
        ----------
        separation : Quantity, length
        primary_spin : Quantity, angular velocity (about A's z axis)
        speed : Quantity, velocity, optional
            Relative speed along +y; default :meth:`BinarySystem.circular_speed`.
        libration : Quantity, angle
            B turned by this angle about z from the synchronous attitude (a free-libration start).
        """
        r = value_in("separation", separation, u.m, "1200 * u.m", shape=())
        spin_a = value_in("primary_spin", primary_spin, u.rad / u.s, "7.7227e-4 * u.rad / u.s", shape=())
        v = (system.circular_speed(r * u.m) if speed is None else speed)
        v = value_in("speed", v, u.m / u.s, "0.1757 * u.m / u.s", shape=())
        angle = value_in("libration", libration, u.rad, "0.01 * u.rad", shape=())
        half = 0.5 * angle
        return cls(system, [r, 0.0, 0.0] * u.m, [0.0, v, 0.0] * u.m / u.s, (1.0, 0.0, 0.0, 0.0),
                   [0.0, 0.0, spin_a] * u.rad / u.s, (math.cos(half), 0.0, 0.0, math.sin(half)),
                   [0.0, 0.0, v / r] * u.rad / u.s)

    def core_state(self):
        """The (20,) SI state of :mod:`spinorbit.core.binary.equations`, checked (contact, finite, unit q)."""
        y = np.empty(core.BINARY_STATE_SIZE)
        y[core.POSITION:core.POSITION + 3] = value_in("separation", self.separation, u.m, "[1200, 0, 0] * u.m",
                                                      shape=(3,))
        y[core.VELOCITY:core.VELOCITY + 3] = value_in("velocity", self.velocity, u.m / u.s,
                                                      "[0, 0.1757, 0] * u.m / u.s", shape=(3,))
        y[core.QUAT_A:core.QUAT_A + 4] = _unit_quaternion("primary_quaternion", self.primary_quaternion)
        y[core.OMEGA_A:core.OMEGA_A + 3] = value_in("primary_spin", self.primary_spin, u.rad / u.s,
                                                    "[0, 0, 7.7e-4] * u.rad / u.s", shape=(3,))
        y[core.QUAT_B:core.QUAT_B + 4] = _unit_quaternion("secondary_quaternion", self.secondary_quaternion)
        y[core.OMEGA_B:core.OMEGA_B + 3] = value_in("secondary_spin", self.secondary_spin, u.rad / u.s,
                                                    "[0, 0, 1.46e-4] * u.rad / u.s", shape=(3,))
        check_separation(float(np.linalg.norm(y[:3])), self.system.contact_distance.to_value(u.m))
        return y

    def with_velocity_change(self, delta_v):
        """The state after an impulsive change Δv (Quantity (3,), inertial axes) of the secondary's velocity.

        A's velocity is unchanged, so the relative velocity changes by Δv. B's spin is unchanged: the
        impulse is applied through its centre of mass.
        """
        dv = value_in("delta_v", delta_v, u.m / u.s, "[0, -2.7e-3, 0] * u.m / u.s", shape=(3,))
        return BinaryState(self.system, self.separation, self.velocity + dv * u.m / u.s, self.primary_quaternion,
                           self.primary_spin, self.secondary_quaternion, self.secondary_spin)

    @property
    def energy(self):
        """Total energy (J)."""
        return core.binary_energy(self.core_state(), self.system.model()) * u.J

    def secondary_long_axis(self):
        """B's long (x) axis on the inertial axes."""
        return quat_to_matrix(np.asarray(self.secondary_quaternion, dtype=float))[:, 0]


@finite_result("momentum_impulse", "β m v / M overflows double precision")
def momentum_impulse(impactor_mass, impactor_velocity, beta, target_mass):
    """Δv of a target hit by an impactor, with momentum enhancement β: Δv = β m v / M.

    β = 1 is a perfectly inelastic impact; β > 1 counts the momentum the ejecta carry away backwards
    (the DART definition, Cheng et al. 2023, Nature 616, 457, for an impact along the velocity).

    Parameters
    ----------
    impactor_mass : Quantity, mass
    impactor_velocity : Quantity (3,), velocity, relative to the target
    beta : float, ≥ 1 in practice (any finite value is accepted: β < 1 would mean momentum lost)
    target_mass : Quantity, mass
    """
    m = value_in("impactor_mass", impactor_mass, u.kg, "579.4 * u.kg", shape=())
    v = value_in("impactor_velocity", impactor_velocity, u.m / u.s, "[0, -6144.9, 0] * u.m / u.s", shape=(3,))
    big_m = value_in("target_mass", target_mass, u.kg, "4.3e9 * u.kg", shape=())
    b = value_in("beta", beta, u.dimensionless_unscaled, "3.61", shape=())
    if not m > 0 or not big_m > 0:
        raise ValueError(f"impactor_mass, target_mass: expected positive masses, got {m} kg and {big_m} kg.")
    return b * m * v / big_m * u.m / u.s
