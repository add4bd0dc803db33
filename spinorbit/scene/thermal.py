"""Saying "this body feels sunlight": :class:`ThermalModel`, the recoil of a shape with its units and checks.

A :class:`ThermalModel` is what a :class:`~spinorbit.scene.Scene` takes as ``thermal=``: a shape's
Rubincam recoil in its compact representation (:func:`spinorbit.shape.thermal_block`, the kernels of
:mod:`spinorbit.core.model.thermal`), the density that makes the body's moments, and optionally the
nutation damping's rigidity × quality factor (:mod:`spinorbit.core.averaging.dissipation`). It is a
frozen description, like a :class:`~spinorbit.RigidBody`: an ensemble member or a fit varies it by
building another one (:meth:`ThermalModel.from_shape` costs one facet sum).

Units: inputs and outputs are astropy Quantities; the block inside is in the orbit-driven runs'
au, day and kg m² (torque in kg m² day⁻² for moments in kg m²).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.quantities import finite_result, require_quantity, value_in
from spinorbit.scene.errors import SceneError

__all__ = ["ThermalModel", "ThermalInputError", "VanishingYorpWarning", "DEFAULT_K3_SQUARED", "MOMENT_RTOL",
           "validate_thermal", "warn_if_yorp_vanishes"]

#: Burns & Safronov's (1973) shape factor K₃² ≈ 0.01 for a moderately elongated body, the value
#: Harris (1994) uses for the damping time scales of tumbling asteroids.
DEFAULT_K3_SQUARED = 0.01
#: Relative agreement asked of the body's moments and the shape's (InertiaMismatchError above it):
#: a body built by rigid_body_from_shape agrees to rounding; published moments carry ~6 digits.
MOMENT_RTOL = 1e-6


class ThermalInputError(SceneError):
    """A thermal model or its use that cannot be run (message: what was expected, what arrived, what to do)."""


def _real(name, value, example):
    """A dimensionless real number (Python's, numpy's of any width, or a dimensionless Quantity), finite."""
    if isinstance(value, (bool, np.bool_)):
        raise ThermalInputError(f"{name} expects a number such as {example}; got {value!r}.")
    return value_in(name, value, u.dimensionless_unscaled, example, shape=())


class VanishingYorpWarning(UserWarning):
    """The shape is mirror-symmetric in its three principal planes, so its YORP is zero by symmetry.

    The mean recoil torque then has no part that changes the spin rate, the obliquity or the tumbling
    state (S, Z, H); a part that precesses the spin axis about the orbit normal is left.
    """


def _positive(name, value, unit, example):
    require_quantity(name, value, unit, example)
    if not isinstance(value, u.Quantity) or not value.isscalar or not value.unit.is_equivalent(unit):
        raise ThermalInputError(f"{name} expects a scalar Quantity in {unit} such as {example}; got {value!r}.")
    magnitude = float(value.to_value(unit))
    if not (math.isfinite(magnitude) and magnitude > 0.0):
        raise ThermalInputError(f"{name} expects a positive finite value such as {example}; got {value!r}.")
    return magnitude


@dataclass(frozen=True, eq=False)
class ThermalModel:
    """Sunlight's recoil on a shape (Rubincam 2000, zero conductivity) and the body's nutation damping.

    Build with :meth:`from_shape`. Attributes: ``shape``, ``properties`` (its constant-density
    :class:`~spinorbit.shape.ShapeMassProperties`), ``block`` (the recoil in au/day/kg m²: its facets,
    and the harmonics of degree ``degree``), ``torque`` (what the full route evaluates: "facets" or
    "harmonics"), ``efficiency``, ``density``, ``mu_q`` (Pa, or None: no damping), ``k3_squared``,
    ``mirror_planes`` (the principal axes whose normal plane mirrors the shape,
    :func:`spinorbit.shape.symmetry.mirror_planes`).
    The state's body axes are the shape's principal axes (as :func:`~spinorbit.shape.rigid_body_from_shape`
    makes them), where the block's torque is expressed.
    """

    shape: object
    properties: object
    block: np.ndarray
    degree: int
    efficiency: float
    density: u.Quantity
    mu_q: u.Quantity | None = None
    k3_squared: float = DEFAULT_K3_SQUARED
    torque: str = "harmonics"
    mirror_planes: tuple = ()

    @classmethod
    def from_shape(cls, shape, density, degree=None, efficiency=1.0, mu_q=None, k3_squared=DEFAULT_K3_SQUARED,
                   torque="harmonics"):
        """The recoil of ``shape`` at constant ``density``, with nutation damping if ``mu_q`` is given.

        Parameters
        ----------
        shape : spinorbit.shape.Shape
        density : Quantity
            Bulk density (kg/m³), which makes the shape's moments and the damping's ρ.
        degree : int, optional
            Degree L of the representation in the Sun's direction
            (:data:`spinorbit.shape.thermal.DEFAULT_THERMAL_DEGREE`; errors per degree in docs/thermal.md),
            what the full route evaluates with ``torque="harmonics"``.
        efficiency : float
            η of :func:`spinorbit.core.model.thermal.recoil_pressure`: 1 when all the light is
            re-emitted or scattered as by a Lambertian surface, 1 − A for a Bond albedo A whose
            reflected part is not Lambertian.
        mu_q : Quantity, optional
            Rigidity × quality factor μQ (Pa) of the nutation damping (Burns & Safronov 1973;
            ~10⁹–10¹¹ Pa for rubble piles to monoliths); None: no damping.
        k3_squared : float
            Burns & Safronov's shape factor K₃² (dimensionless, :data:`DEFAULT_K3_SQUARED`).
        torque : {"harmonics", "facets"}
            What the full route sums at each step: the degree-L harmonics (smooth in the Sun's direction,
            a few hundred ns at L = 8, but their truncation moves the mean YORP torque by up to tens of
            per cent of itself) or the facets themselves (exact; about 1.5 ns a facet, but each facet's
            terminator is a kink the integrator's error control meets at tight tolerances: docs/thermal.md
            measures both). The mean route averages the facets exactly either way.

        Raises
        ------
        ThermalInputError
            Not a Shape, a density or μQ that is not a positive Quantity, η outside (0, 1], K₃² ≤ 0.
        """
        from spinorbit.shape import Shape, shape_mass_properties, thermal_block
        from spinorbit.shape.symmetry import mirror_planes
        from spinorbit.shape.thermal import DEFAULT_THERMAL_DEGREE, TORQUES

        if not isinstance(shape, Shape):
            raise ThermalInputError(f"shape expects a spinorbit.shape.Shape (read_obj, read_icq, "
                                    f"gaussian_random_sphere, …); got {type(shape).__name__}.")
        _positive("density", density, u.kg / u.m**3, "2000 * u.kg / u.m**3")
        if mu_q is not None:
            _positive("mu_q", mu_q, u.Pa, "1e9 * u.Pa")
        efficiency = _real("efficiency", efficiency, "0.9")
        if not 0.0 < efficiency <= 1.0:
            raise ThermalInputError(f"efficiency expects 0 < η ≤ 1 (the Lambertian share of the sunlight, 1 − A "
                                    f"for a non-Lambertian Bond albedo A); got {efficiency!r}.")
        k3_squared = _real("k3_squared", k3_squared, str(DEFAULT_K3_SQUARED))
        if not k3_squared > 0.0:
            raise ThermalInputError(f"k3_squared expects Burns & Safronov's positive shape factor K₃² (about "
                                    f"{DEFAULT_K3_SQUARED}); got {k3_squared!r}.")
        if torque not in TORQUES:
            raise ThermalInputError(f"torque expects one of {TORQUES} (the facet sum itself, or its degree-L "
                                    f"harmonics); got {torque!r}.")
        if degree is not None and torque == "facets":
            raise ThermalInputError(f"degree {degree!r} is the harmonics' degree, but torque='facets' sums the facets "
                                    "themselves: give torque='harmonics' with it, or leave degree out.")
        degree = DEFAULT_THERMAL_DEGREE if degree is None else degree
        properties = shape_mass_properties(shape, density=density)
        try:
            block = thermal_block(shape, properties, degree=degree, efficiency=float(efficiency), torque=torque)
        except ValueError as error:
            raise ThermalInputError(f"degree: {error}") from None
        block.flags.writeable = False
        return cls(shape, properties, block, int(degree), float(efficiency), density.to(u.kg / u.m**3),
                   None if mu_q is None else mu_q.to(u.Pa), float(k3_squared), torque,
                   mirror_planes(shape, properties))

    # ------------------------------------------------------------------------------------------

    @property
    def mean_radius(self):
        """Radius of the sphere of the shape's volume (m): the R of the damping time scale."""
        return ((3.0 * self.properties.volume / (4.0 * math.pi)) ** (1.0 / 3.0)).to(u.m)

    @property
    def damping_constant(self):
        """k = μQ/(ρ K₃² R²) in day⁻² (τ_D = k/ω³, :func:`spinorbit.core.averaging.dissipation.damping_constant`); 0 without μQ."""
        from spinorbit.core.averaging.dissipation import damping_constant

        if self.mu_q is None:
            return 0.0
        return damping_constant(float(self.mu_q.to_value(u.Pa)), float(self.density.to_value(u.kg / u.m**3)),
                                float(self.mean_radius.to_value(u.m)), self.k3_squared)

    @finite_result("ThermalModel.damping_time", "τ_D = k/ω³ overflows double precision at so slow a spin")
    def damping_time(self, spin_rate):
        """Burns & Safronov's τ_D = μQ/(ρ K₃² R² ω³) at a spin rate (angle/time Quantity, > 0), in years.

        Raises
        ------
        ThermalInputError
            No damping (``mu_q`` None), or a spin rate that is not a positive angular velocity.
        NonFiniteError
            A NaN or infinite spin rate, or one so slow that τ_D overflows.
        """
        if self.mu_q is None:
            raise ThermalInputError("damping_time needs the damping: give ThermalModel.from_shape(..., mu_q=1e9 * u.Pa).")
        omega = value_in("spin_rate", spin_rate, u.rad / u.day, "2 * u.cycle / u.day", shape=())
        if not omega > 0.0:
            raise ThermalInputError(f"spin_rate expects a positive angular velocity such as 2 * u.cycle / u.day; got "
                                    f"{spin_rate!r}. A body that does not spin has no nutation to damp (τ_D = k/ω³ "
                                    "is infinite); its sign is the direction, give the rate |ω|.")
        return (self.damping_constant / omega**3 * u.day).to(u.yr)

    def check_body(self, body):
        """The body's moments against the shape's at this density, or :class:`~spinorbit.shape.InertiaMismatchError`.

        The block's torque is in kg m² day⁻², so the body needs absolute moments (kg m² or any
        moment-of-inertia unit); moment ratios are refused with :class:`ThermalInputError`.
        """
        from spinorbit.shape import check_moments

        if body.moment_unit.physical_type != "moment of inertia":
            raise ThermalInputError(
                f"the body's moments are {body.moment_unit.physical_type} ratios, but sunlight's torque needs them "
                "in kg m² (its size against the spin is what YORP changes): build the body with "
                "rigid_body_from_shape(shape, density=...) or give RigidBody the moments in kg m².")
        check_moments(body, self.properties, rtol=MOMENT_RTOL)

    def block_for(self, body):
        """The block scaled to the body's moment unit (torque in [moment unit] day⁻²), after :meth:`check_body`."""
        from spinorbit.core.model.thermal import TH_PRESSURE

        self.check_body(body)
        block = np.array(self.block)
        block[TH_PRESSURE] *= float((1.0 * u.kg * u.m**2).to_value(body.moment_unit))
        return block

    @finite_result("ThermalModel.torque_bound", "the pressure P/d² overflows double precision so close to the Sun")
    def torque_bound(self, distance):
        """A bound on |T| at heliocentric ``distance`` (length Quantity): P(d) Σ_k A_k |r_k × n_k| (N m)."""
        from spinorbit.core.model.thermal import recoil_pressure
        from spinorbit.shape import principal_facets

        d_au = _positive("distance", distance, u.au, "1.5 * u.au")
        normals, areas, centroids = principal_facets(self.shape, self.properties)
        lever = float(np.sum(areas * np.linalg.norm(np.cross(centroids, normals), axis=1)))
        return recoil_pressure(self.efficiency) / d_au**2 * lever * u.N * u.m

    @finite_result("ThermalModel.force_and_torque", "the pressure P/d² overflows double precision so close to the Sun")
    def force_and_torque(self, sun_direction, distance):
        """Recoil force (N) and torque (N m) for the Sun along ``sun_direction`` (body principal axes) at ``distance``.

        Evaluates the compact representation (:func:`spinorbit.core.model.thermal.thermal_force_torque_xyz`).

        Raises
        ------
        ThermalInputError
            A zero or non-finite direction, a non-positive distance.
        """
        from spinorbit.core.model.thermal import thermal_force_torque_xyz

        d_au = _positive("distance", distance, u.au, "1.5 * u.au")
        s = np.asarray(sun_direction, dtype=float)
        if s.shape != (3,) or not np.all(np.isfinite(s)) or not np.linalg.norm(s) > 0.0:
            raise ThermalInputError(f"sun_direction expects a non-zero finite 3-vector (body principal axes); got {s!r}.")
        fx, fy, fz, tx, ty, tz = thermal_force_torque_xyz(s[0], s[1], s[2], d_au, self.block, 0)
        to_si = 1.0 / 86400.0**2  # kg m / day² per N, kg m² / day² per N m
        return np.array([fx, fy, fz]) * to_si * u.N, np.array([tx, ty, tz]) * to_si * u.N * u.m

    @property
    def yorp_vanishes(self):
        """True when the shape mirrors itself in all three principal planes: no mean change of S, Z, H (YORP)."""
        return len(self.mirror_planes) == 3

    @property
    def torque_text(self):
        """What the full route evaluates, in words (plans and reprs)."""
        return "the facet sum" if self.torque == "facets" else f"harmonics of degree {self.degree}"

    def __repr__(self):
        damping = f", μQ = {self.mu_q:.3g}" if self.mu_q is not None else ""
        return (f"ThermalModel({len(self.shape)} facets, {self.torque_text}, η = {self.efficiency:g}, "
                f"ρ = {self.density:.4g}{damping})")


def warn_if_yorp_vanishes(thermal):
    """Warn (:class:`VanishingYorpWarning`) when a run's shape has no mean YORP torque by symmetry."""
    import warnings

    if thermal.yorp_vanishes:
        warnings.warn(
            f"the shape ({len(thermal.shape)} facets) mirrors itself in its three principal planes, like a triaxial "
            "ellipsoid or a box, so its YORP is zero by symmetry (Rubincam 2000; docs/thermal.md): the mean recoil "
            "changes neither the spin rate, nor the obliquity, nor the tumbling state; only a precession of the "
            "spin axis about the orbit normal and the periodic terms are left. Use an irregular shape (read_obj, "
            "gaussian_random_sphere) for a YORP evolution.", VanishingYorpWarning, stacklevel=4)


def validate_thermal(state, thermal, thermal_route, orbit, perturbers, epoch, times):
    """Check a thermal scene's inputs (:class:`~spinorbit.scene.Scene` with ``thermal=``), or raise.

    Raises
    ------
    ThermalInputError
        Not a ThermalModel, an unknown route, no orbit or not a Kepler orbit, perturbers other than
        the Sun, output times not after the epoch, moment ratios instead of moments, or an
        Orbit.kepler without ``thermal=``.
    spinorbit.shape.InertiaMismatchError
        The body's moments contradict the shape's at the model's density.
    """
    from spinorbit.scene.inputs import validate_times
    from spinorbit.scene.thermal_planning import THERMAL_ROUTES

    if thermal is None:
        raise ThermalInputError("orbit=Orbit.kepler(...) is the Sun alone on a fixed ellipse, for scenes that feel "
                                "sunlight: give thermal=ThermalModel.from_shape(...), or use Orbit.from_elements "
                                "for a gravity scene among DE421's planets.")
    if not isinstance(thermal, ThermalModel):
        raise ThermalInputError(f"thermal expects a spinorbit.scene.ThermalModel (ThermalModel.from_shape(shape, "
                                f"density=...)); got {type(thermal).__name__}.")
    if thermal_route not in THERMAL_ROUTES:
        raise ThermalInputError(f"thermal_route expects one of {THERMAL_ROUTES}; got {thermal_route!r}.")
    if orbit is None:
        raise ThermalInputError("thermal needs the body's heliocentric orbit (the Sun's direction and distance): "
                                "give orbit=Orbit.kepler(a, e, inc, raan, argp, mean_anomaly, epoch).")
    if getattr(orbit, "kind", None) != "kepler":
        raise ThermalInputError(
            f"thermal scenes run on a heliocentric Kepler orbit (the orbit the mean YORP run averages over); got an "
            f"orbit of kind {getattr(orbit, 'kind', type(orbit).__name__)!r}. Give orbit=Orbit.kepler(...) with the "
            "body's osculating elements.")
    others = [p for p in perturbers if not (isinstance(p, str) and p.lower() == "sun")]
    if others:
        raise ThermalInputError(f"a thermal scene's torques are the Sun's (gravity and recoil) on its Kepler orbit; "
                                f"other perturbers {others!r} are not available there. Leave perturbers empty or ('sun',).")
    validate_times(epoch, times, either_side=False)
    thermal.check_body(state.body)
