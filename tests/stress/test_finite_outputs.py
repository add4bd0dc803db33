"""Extreme but representable inputs: a finite result or a specific refusal, never a NaN, an inf or a bare
arithmetic error (issue 36, classes 4 and 7).

Inputs are checked once at the units layer's entry (``spinorbit.quantities.value_in``) and results once
on the way out (``spinorbit.quantities.finite_result``, ``spinorbit.core.errors.require_finite_result``).
"""

import numpy as np
import pytest
from astropy import units as u

from spinorbit.binary import BinarySystem, Figure, momentum_impulse
from spinorbit.core.binary.errors import ContactError
from spinorbit.core.errors import NonFiniteError
from spinorbit.core.free_motion.flow import torque_free_states_many
from spinorbit.core.model.polyhedron import InvalidMeshError
from spinorbit.scene import ThermalModel
from spinorbit.scene.thermal import ThermalInputError
from spinorbit.shape import (
    ShapeFileError,
    ellipsoid_shape,
    gaussian_random_sphere,
    icq_grid,
    read_icq,
    read_obj,
    write_icq,
)
from spinorbit.yarkovsky import yarkovsky_drift

DENSITY = 2 * u.g / u.cm ** 3
YARKOVSKY = dict(radius=150 * u.m, density=2000 * u.kg / u.m ** 3, heat_capacity=680 * u.J / (u.kg * u.K),
                 rotation_period=6 * u.h, obliquity=0 * u.deg, semi_major_axis=1.5 * u.au,
                 thermal_inertia=300 * u.J / (u.m ** 2 * u.K * u.s ** 0.5))


@pytest.fixture(scope="module")
def thermal():
    shape = gaussian_random_sphere(0.2 * u.km, 0.1, seed=1, subdivisions=2)
    return ThermalModel.from_shape(shape, 2000 * u.kg / u.m ** 3, mu_q=1e9 * u.Pa)


@pytest.mark.parametrize("change, message", [
    (dict(radius=1e200 * u.m), r"yarkovsky_drift: the arithmetic overflowed for radius=1e\+200 m"),
    (dict(semi_major_axis=1e-300 * u.au), r"yarkovsky_drift: the arithmetic divided by zero .*semi_major_axis=1e-300 AU"),
])
def test_yarkovsky_drift_of_an_extreme_sphere_is_refused_naming_its_inputs(change, message):
    with pytest.raises(NonFiniteError, match=message):
        yarkovsky_drift(**{**YARKOVSKY, **change})


def test_numpy_scalars_of_any_width_are_numbers(thermal):
    # float32 is a real number: the albedo and the efficiency are read in it, to its own precision.
    plain = yarkovsky_drift(**YARKOVSKY, albedo=0.1).total
    narrow = yarkovsky_drift(**YARKOVSKY, albedo=np.float32(0.1)).total
    assert narrow.to_value(u.au / u.Myr) == pytest.approx(plain.to_value(u.au / u.Myr), rel=1e-7)  # 0.1 in float32
    model = ThermalModel.from_shape(thermal.shape, 2000 * u.kg / u.m ** 3, efficiency=np.float32(0.9))
    assert model.efficiency == pytest.approx(0.9, rel=1e-7)
    with pytest.raises(ValueError, match="albedo"):
        yarkovsky_drift(**YARKOVSKY, albedo=True)


def test_the_recoil_next_to_the_sun_is_refused_not_infinite(thermal):
    with pytest.raises(NonFiniteError, match=r"force_and_torque\[0\] for .*distance=1e-300 AU.*\[-?inf"):
        thermal.force_and_torque([1.0, 0.0, 0.0], 1e-300 * u.au)
    with pytest.raises(NonFiniteError, match="torque_bound"):
        thermal.torque_bound(1e-300 * u.au)
    # Far away it is small and finite: an underflow to zero is a representable answer.
    force, torque = thermal.force_and_torque([1.0, 0.0, 0.0], 1e300 * u.au)
    assert np.all(np.isfinite(force.value)) and np.all(np.isfinite(torque.value))


def test_damping_time_refuses_nan_zero_and_overflowing_spin_rates(thermal):
    with pytest.raises(NonFiniteError, match="spin_rate: expected finite numbers"):
        thermal.damping_time(np.nan * u.rad / u.s)
    with pytest.raises(ThermalInputError, match="positive angular velocity .*does not spin"):
        thermal.damping_time(0 * u.rad / u.s)
    with pytest.raises(ThermalInputError, match="positive"):
        thermal.damping_time(-1 * u.cycle / u.day)
    with pytest.raises(NonFiniteError, match="damping_time.*1e-200 rad / s"):
        thermal.damping_time(1e-200 * u.rad / u.s)
    with pytest.raises(u.UnitTypeError, match="spin_rate expects an angular velocity Quantity"):
        thermal.damping_time(1.0)
    # τ_D = k/ω³: one cycle per day against two, a factor 8 (the ratio is exact in binary).
    one, two = thermal.damping_time(1 * u.cycle / u.day), thermal.damping_time(2 * u.cycle / u.day)
    assert (one / two).to_value(u.one) == pytest.approx(8.0, rel=1e-15)


def test_a_sphere_too_large_for_double_precision_is_refused():
    with pytest.raises(NonFiniteError, match=r"Figure.ellipsoid.integrals .*semi_axes=.*1\.e\+200"):
        Figure.sphere("A", 1e200 * u.m, 2 * u.g / u.cm ** 3)
    with pytest.raises(InvalidMeshError, match=r"spans 2e\+197 .*outside \[1e-40, 1e\+40\]"):
        ellipsoid_shape([1e200, 1e200, 1e200] * u.m, subdivisions=1)
    shape = ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=1)
    with pytest.raises(NonFiniteError, match=r"shape_mass_properties: the inertia tensor \(ρ = 1e\+300"):
        ThermalModel.from_shape(shape, 1e300 * u.kg / u.m ** 3)


def test_torque_free_states_many_refuses_nan_inputs():
    q, momentum, moments = np.array([[1.0, 0, 0, 0]]), np.array([[0.1, 0.2, 1.0]]), np.array([1.0, 2.0, 3.0])
    with pytest.raises(NonFiniteError, match=r"times: expected finite times .*\[nan\]"):
        torque_free_states_many(q, momentum, moments, np.array([np.nan]))
    with pytest.raises(NonFiniteError, match="momenta"):
        torque_free_states_many(q, np.array([[0.1, np.inf, 1.0]]), moments, np.array([1.0]))
    with pytest.raises(NonFiniteError, match="quaternions"):
        torque_free_states_many(np.array([[np.nan, 0, 0, 0]]), momentum, moments, np.array([1.0]))
    with pytest.raises(ValueError, match="magnitude ≤ 1e\\+150"):
        torque_free_states_many(q, np.array([[0.1, 0.2, 1e200]]), moments, np.array([1.0]))
    attitudes, momenta = torque_free_states_many(q, momentum, moments, np.array([0.0, 1e6]))
    assert np.all(np.isfinite(attitudes)) and np.all(np.isfinite(momenta))


def test_a_nan_vertex_in_a_shape_file_is_named_by_its_line(tmp_path):
    grid = icq_grid(lambda d: np.ones(d.shape[0]) * u.km, 2)
    write_icq(tmp_path / "ok.icq", grid)
    lines = (tmp_path / "ok.icq").read_text().splitlines()
    lines[4] = "nan 0.1 0.2"
    (tmp_path / "bad.icq").write_text("\n".join(lines) + "\n")
    with pytest.raises(ShapeFileError, match=r"bad.icq, vertex line 4: expected three finite numbers 'x y z'; got 'nan"):
        read_icq(tmp_path / "bad.icq", u.km)
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n")
    with pytest.raises(ShapeFileError, match=r"bad.obj, line 4: expected 'v x y z' with three finite numbers"):
        read_obj(tmp_path / "bad.obj", u.km)


def test_binary_helpers_refuse_what_they_cannot_compute():
    with pytest.raises(NonFiniteError, match=r"momentum_impulse\b.*β m v / M overflows"):
        momentum_impulse(1e300 * u.kg, [0, -1e300, 0] * u.m / u.s, 3.6, 1e-300 * u.kg)
    system = BinarySystem(Figure.sphere("A", 300 * u.m, DENSITY), Figure.sphere("B", 50 * u.m, DENSITY))
    # Inside the contact distance (350 m) the series diverges: no circular speed (it was NaN at 1e-300 m).
    with pytest.raises(ContactError, match="the separation asked for"):
        system.circular_speed(1e-300 * u.m)
    speed = system.circular_speed(1200 * u.m)
    total = (system.primary.mass + system.secondary.mass).to_value(u.kg)
    # Two spheres: Kepler's √(G M / r) (1e-12: the order-2 field of spheres, rounded).
    assert speed.to_value(u.m / u.s) == pytest.approx(np.sqrt(6.6743e-11 * total / 1200), rel=1e-12)
