"""Units never guessed (docs/conventions.md, "Units"): the public API refuses a bare number for a dimensional argument.

The walk covers every function, constructor and method that the user-facing modules export (:data:`SCOPE`):
each parameter is either named in :data:`DIMENSIONAL` with a call that works, or listed as dimensionless or
non-numeric in :data:`NOT_DIMENSIONAL` (for that callable or for every one), or carries its unit in its name
(``span_days``, ``tolerance_arcsec``). A parameter in none of these fails the walk, so a new argument is
classified when it is added. Each dimensional parameter then gets a bare float (a list of floats for a
vector) in an otherwise valid call, which must raise ``QuantityInputError`` naming the parameter, saying that
a bare number arrived and showing a Quantity to copy.

Outside the walk, with their reasons: the core (``spinorbit.core``), unit-agnostic by design; the records
that the package fills and returns (:data:`RECORDS`: results, plans, published data), whose fields are
documented with their units; the fitter's residual hooks, which receive the core's arrays; and the
plumbing modules between the units layer and the core (``spinorbit.spin_forms``, ``spinorbit.frames``,
``spinorbit.orbital_elements``, ``spinorbit.scene.bounds``, …), plain floats with the unit in each name or
unit-agnostic.
"""

import functools
import importlib
import inspect
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit.quantities import QuantityInputError

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_public_paths import PUBLIC_MODULES, _defined_names  # noqa: E402

#: The modules a user calls: the doors above the core and the published bodies and effects.
SCOPE = ("spinorbit", "spinorbit.scene", "spinorbit.ensemble", "spinorbit.ensemble.apophis", "spinorbit.binary",
         "spinorbit.shape", "spinorbit.fit", "spinorbit.photometry", "spinorbit.data.asteroids",
         "spinorbit.data.didymos", "spinorbit.data.dart", "spinorbit.yarkovsky")

#: Records the package fills and returns, or tables of published numbers: not typed in by a user. Their
#: docstrings give each field's unit; the values a user passes on go through the walked callables.
RECORDS = {
    "CanonicalElements", "BinaryRun", "LibrationComponents", "MutualOrbit", "FitResult", "Plan", "PerturberEstimate",
    "Decision", "SceneResult", "SceneResults", "ScenePlans", "ShapeMassProperties", "YarkovskyDrift",
    "EncounterGeometry", "PublishedState", "OsculatingElements", "HeliocentricDirections",
    # Figure(...) is the record its constructors fill (ellipsoid, sphere, from_shape, from_inertia: walked);
    # its own fields carry their unit in their names (circumscribing_radius_m, semi_axes_m).
    "Figure", "ViewingGeometry",
}
#: Methods that hand the core's plain arrays (rad/day, principal axes) between the fitter and an observation.
CORE_HOOKS = {"residuals", "principal_quaternion"}

#: Parameters that are never dimensional in any callable of the scope.
NOT_DIMENSIONAL_ANYWHERE = {
    # objects, names, choices, flags
    "body", "state", "states", "system", "primary", "secondary", "shape", "properties", "orbit", "sim", "simulation",
    "particle", "geometry", "name", "names", "path", "unit", "frame", "axes", "mode", "reference", "elements",
    "integrator", "route", "backend", "law", "shadowing", "self_shadowing", "source", "sources", "progress",
    "plan", "skip", "executor", "checkpoint", "keep_tables", "return_details", "physical", "closed_forms",
    "make_scene", "function", "perturbers", "bodies", "target", "thermal", "thermal_route", "quantities", "options",
    "extra_forces", "non_gravitational", "element_set", "kind", "fit_moments", "observations", "first_guess",
    "multi_start", "centre", "relative", "shared", "what", "block", "rng", "distributions", "parameters", "ax",
    "batch_integrators", "chunk", "indices", "index", "sun", "initial", "stats", "times_of", "radius_function",
    "torque", "data", "table", "metadata", "magnitude", "magnitude_error", "filter", "filters", "observer", "session",
    "require_uncertainties", "calibrated", "phase_function", "digits", "outcome_units",
    # times as astropy Time (their scale is checked where they are read)
    "epoch", "time", "times", "start", "end", "at", "span", "body_times",
    # integers and counts
    "order", "subdivisions", "degree", "degree_max", "seed", "n", "q", "samples", "shadow_samples", "max_steps",
    "max_nfev", "chunk_size", "spawn_key", "entropy", "supported_order",
    # arrays without a unit: unit quaternions, rotations, directions, faces, voxel masks, ICQ grids in Quantities
    "quaternion", "quaternions", "attitude_matrix", "to_principal", "faces", "occupied", "grid", "body_axis",
    "direction", "sun_direction", "sun_directions", "observer_directions", "orbit_normal", "primary_quaternion",
    "secondary_quaternion", "shadow_grid", "attitudes",
    # dimensionless numbers: ratios, fractions, relative tolerances, efficiencies, eccentricities
    "moments", "moment_ratios", "i1_i3", "i2_i3", "e", "eccentricity", "beta", "efficiency", "k3_squared", "albedo",
    "emissivity", "rtol", "sample_tolerance", "correlation_threshold", "condition_threshold", "fraction_of_p_psi",
    "fraction_about_momentum", "phase_psi", "phase_momentum", "lambert_weight", "nu", "low", "high", "mean",
    "sphere_ratio",
}
#: Parameters dimensionless only in one callable (elsewhere the same name may be a Quantity).
NOT_DIMENSIONAL_IN = {
    "gaussian_random_sphere": {"sigma"},  # the radius's relative standard deviation
    "Orbit": {"description", "de421_planets", "kepler_elements"},  # filled by Orbit's constructors (walked)
    "Scene.sample_perturbers": {"tolerance"},  # the relative position tolerance of the sampling
    "Scene.grid_of": {"tolerance"},
    "closest_approach": {"near"},  # an astropy Time
    "aligning_quaternion": {"v_body", "v_inertial"},  # directions
    "ThermalModel": {"density", "mu_q", "torque", "mirror_planes"},  # the record from_shape fills (walked)
    # a magnitude: astropy's mag is dimensionless (a logarithm of a flux ratio), and photometry writes it bare
    "HG1G2": {"H", "G1", "G2"},
    "LinearExponential": {"H", "amplitude"},
    "apophis_rotation_state": {"phase"},  # a fraction of P_psi in [0, 1)
    "reshaped": {"axis_ratios"},  # Dimorphos's a/b and a/c after the impact
    "Normal": {"sigma"},  # a sampler of numbers or Quantities, for the user's own make_scene
    "free_members_table": {"parameters"},
    # an sbpy table (its Quantities read), a row index; phase goes as it came to from_pole, whose bare-number
    # refusal the walk checks (importing sbpy here would raise astropy's deprecation warning at collection)
    "RotationState.from_sbpy": {"phys", "row", "phase"},
    "Orbit.from_sbpy": {"row", "kepler"},  # an sbpy table or row, and a switch
}
#: A unit in the parameter's own name: the number is in that unit, not guessed.
UNIT_SUFFIX = re.compile(r"(^|_)(days?|au|km|km2|m|s|kg|si|deg|rad|arcsec)$")

EPOCH = Time("2020-01-01T00:00:00", scale="tdb")


def _body():
    from spinorbit import RigidBody
    return RigidBody([1.0, 1.2, 1.5])


def _state():
    from spinorbit import RotationState
    return RotationState(_body(), [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 3.0] * u.rad / u.day, epoch=EPOCH)


def _shape():
    from spinorbit.shape import ellipsoid_shape
    return ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=1)


@functools.lru_cache(maxsize=None)
def _calls():
    """{callable's qualified name: (call(**overrides), {dimensional parameter: bare value})}.

    ``call()`` is a valid call with Quantities for every dimensional parameter; ``call(name=bare)`` swaps one.
    """
    from spinorbit import RigidBody, RotationState
    from spinorbit.binary import BinaryState, BinarySystem, Figure, HeliocentricOrbit, momentum_impulse
    from spinorbit.data.dart import along_track, dart_state, dart_system
    from spinorbit.data.didymos import didymos_state
    from spinorbit.ensemble import free_members_table
    from spinorbit.fit import AttitudeObservation, AxisObservation, PeriodObservation, SpinRateObservation
    from spinorbit.photometry import Ellipsoid, LinearExponential
    from spinorbit.scene import EphemerisPerturber, FixedPerturber, Orbit, Scene, ThermalModel
    from spinorbit.shape import (box_shape, ellipsoid_shape, gaussian_random_sphere, icq_grid, rigid_body_from_shape,
                                 shape_mass_properties, voxel_shape)
    from spinorbit.shape.mesh import Shape
    from spinorbit.yarkovsky import yarkovsky_drift

    def call(target, /, **valid):
        return lambda **bad: target(**{**valid, **bad})

    body, shape = _body(), _shape()
    rate = u.rad / u.day
    sphere = Figure.sphere("A", 300 * u.m, 2000 * u.kg / u.m**3)
    system = BinarySystem(sphere, Figure.sphere("B", 50 * u.m, 2000 * u.kg / u.m**3), order=2)
    binary = dict(system=system, separation=[1200.0, 0, 0] * u.m, velocity=[0, 0.1, 0] * u.m / u.s,
                  primary_quaternion=(1, 0, 0, 0), primary_spin=[0, 0, 7e-4] * u.rad / u.s,
                  secondary_quaternion=(1, 0, 0, 0), secondary_spin=[0, 0, 1e-4] * u.rad / u.s)
    thermal = ThermalModel.from_shape(shape, density=2000 * u.kg / u.m**3, degree=2, mu_q=1e9 * u.Pa)
    elements = dict(a=2.5 * u.au, e=0.1, inc=5 * u.deg, raan=10 * u.deg, argp=20 * u.deg, mean_anomaly=30 * u.deg,
                    epoch=EPOCH)
    bare_elements = {"a": 2.5, "inc": 5.0, "raan": 10.0, "argp": 20.0, "mean_anomaly": 30.0}
    tumbling = dict(body=RigidBody([0.61, 0.965, 1.0]), p_psi=263 * u.hour, p_phi=27.38 * u.hour,
                    momentum_lon=250 * u.deg, momentum_lat=-75 * u.deg, phi0=10 * u.deg, theta0=None,
                    psi0=20 * u.deg, epoch=EPOCH)
    spin = [0.0, 0.0, 2.18e-4]
    dart = dart_system()
    return {
        # the front door
        "RigidBody": (call(RigidBody, moments=[1.0, 1.2, 1.5], mass=6e10 * u.kg, radius=0.2 * u.km),
                      {"mass": 6e10, "radius": 0.2}),
        "RotationState": (call(RotationState, body=body, quaternion=[1, 0, 0, 0], angular_velocity=spin * rate),
                          {"angular_velocity": spin}),
        "RotationState.from_matrix": (call(RotationState.from_matrix, body=body, attitude_matrix=np.eye(3),
                                           angular_velocity=spin * rate), {"angular_velocity": spin}),
        "RotationState.from_euler313": (
            call(RotationState.from_euler313, body=body, phi=10 * u.deg, theta=40 * u.deg, psi=70 * u.deg,
                 angular_velocity=spin * rate),
            {"phi": 0.1, "theta": 0.7, "psi": 1.2, "angular_velocity": spin}),
        "RotationState.from_angular_momentum": (
            call(RotationState.from_angular_momentum, body=body, quaternion=[1, 0, 0, 0],
                 angular_momentum=[0, 0, 1.0] * rate), {"angular_momentum": [0.0, 0.0, 1.0]}),
        "RotationState.from_pole": (
            call(RotationState.from_pole, body=body, pole_lon=80 * u.deg, pole_lat=30 * u.deg, period=8 * u.hour,
                 epoch=EPOCH),
            {"pole_lon": 80.0, "pole_lat": 30.0, "period": 8.0, "phase": 10.0}),
        "RotationState.from_tumbling": (
            call(RotationState.from_tumbling, **tumbling),
            {"p_psi": 263.0, "p_phi": 27.38, "momentum_lon": 250.0, "momentum_lat": -75.0, "phi0": 10.0,
             "theta0": 20.0, "psi0": 20.0, "theta_tolerance": 1.0}),
        "RotationState.propagate_torque_free": (call(_state().propagate_torque_free, dt=[0.0, 1.0] * u.day),
                                                {"dt": [0.0, 1.0]}),
        "RotationState.pole": (call(_state().pole), {"max_wobble": 1.0}),
        "RotationState.rotation_class": (call(_state().rotation_class), {"threshold": 1.0}),
        "RotationState.from_andoyer": (
            call(RotationState.from_andoyer, body=body, big_l=1.0 * rate, big_g=2.0 * rate, big_h=0.5 * rate,
                 l=0.1 * u.rad, g=0.2 * u.rad, h=0.3 * u.rad),
            {"big_l": 1.0, "big_g": 2.0, "big_h": 0.5, "l": 0.1, "g": 0.2, "h": 0.3}),
        # shapes
        "Shape": (call(Shape, vertices=shape.vertices, faces=shape.faces), {"vertices": shape.vertices_km}),
        "box_shape": (call(box_shape, half_sides=[1.5, 1.0, 0.7] * u.km), {"half_sides": [1.5, 1.0, 0.7]}),
        "ellipsoid_shape": (call(ellipsoid_shape, semi_axes=[1.0, 0.8, 0.6] * u.km, subdivisions=1),
                            {"semi_axes": [1.0, 0.8, 0.6]}),
        "gaussian_random_sphere": (call(gaussian_random_sphere, radius=1.0 * u.km, sigma=0.1, seed=1, subdivisions=1),
                                   {"radius": 1.0}),
        "voxel_shape": (call(voxel_shape, occupied=np.ones((1, 1, 1), dtype=bool), pitch=0.1 * u.km), {"pitch": 0.1}),
        "icq_mesh": (call(lambda grid: __import__("spinorbit.shape", fromlist=["icq_mesh"]).icq_mesh(grid),
                          grid=icq_grid(lambda d: np.ones(len(d)) * u.km, 2)),
                     {"grid": icq_grid(lambda d: np.ones(len(d)) * u.km, 2).value}),
        "icq_grid": (call(icq_grid, radius_function=lambda d: np.ones(len(d)) * u.km, q=2),
                     {"radius_function": lambda d: np.ones(len(d))}),
        "shape_mass_properties": (call(shape_mass_properties, shape=shape, density=2000 * u.kg / u.m**3),
                                  {"density": 2000.0, "mass": {"mass": 5e12, "density": None}}),
        "rigid_body_from_shape": (call(rigid_body_from_shape, shape=shape, density=2000 * u.kg / u.m**3),
                                  {"density": 2000.0, "mass": {"mass": 5e12, "density": None}}),
        "LinearExponential": (call(LinearExponential, H=15 * u.mag, width=0.1 * u.rad, slope=-0.5 / u.rad),
                              {"width": 0.1, "slope": -0.5}),
        "Ellipsoid": (call(Ellipsoid, semi_axes=[1.0, 0.8, 0.6] * u.km), {"semi_axes": [1.0, 0.8, 0.6]}),
        # scenes
        "Scene": (call(Scene, state=_state(), times=EPOCH + [1.0, 2.0] * u.day),
                  {"tolerance": 1e-6, "pa_threshold": 1.0}),
        "Orbit.circular": (call(Orbit.circular, radius=2.5 * u.au), {"radius": 2.5}),
        "Orbit.approaches": (call(Orbit.de421("moon").approaches, body="earth", start=EPOCH, end=EPOCH + 30 * u.day),
                             {"max_distance": 0.05}),
        "Orbit.kepler": (call(Orbit.kepler, **elements), bare_elements),
        "Orbit.from_elements": (call(Orbit.from_elements, **elements), bare_elements),
        "Orbit.from_state": (call(Orbit.from_state, position=[1.0, 0, 0] * u.au, velocity=[0, 30.0, 0] * u.km / u.s,
                                  epoch=EPOCH), {"position": [1.0, 0, 0], "velocity": [0, 30.0, 0]}),
        "FixedPerturber": (call(FixedPerturber, name="x", gm=1e-9 * u.au**3 / u.day**2, position=[1.0, 0, 0] * u.au),
                           {"gm": 1e-9, "position": [1.0, 0, 0]}),
        "EphemerisPerturber": (call(EphemerisPerturber, name="x", gm=1e-9 * u.au**3 / u.day**2,
                                    function=lambda days: (np.ones((len(days), 3)), np.zeros((len(days), 3)))),
                               {"gm": 1e-9}),
        "ThermalModel.from_shape": (call(ThermalModel.from_shape, shape=shape, density=2000 * u.kg / u.m**3, degree=2,
                                         mu_q=1e9 * u.Pa), {"density": 2000.0, "mu_q": 1e9}),
        "ThermalModel.damping_time": (call(thermal.damping_time, spin_rate=2 * u.cycle / u.day), {"spin_rate": 12.0}),
        "ThermalModel.torque_bound": (call(thermal.torque_bound, distance=1.5 * u.au), {"distance": 1.5}),
        "ThermalModel.force_and_torque": (call(thermal.force_and_torque, sun_direction=[1.0, 0, 0], distance=1.5 * u.au),
                                          {"distance": 1.5}),
        # ensembles
        "free_members_table": (call(free_members_table, moments=[0.6, 0.9, 1.0], quaternions=[[1.0, 0, 0, 0]],
                                    angular_velocities=[[0.1, 0, 2.0]] * rate, elapsed=3.0 * u.day),
                               {"angular_velocities": [[0.1, 0, 2.0]], "elapsed": 3.0}),
        # binaries
        "BinaryState": (call(BinaryState, **binary),
                        {"separation": [1200.0, 0, 0], "velocity": [0, 0.1, 0], "primary_spin": [0, 0, 7e-4],
                         "secondary_spin": [0, 0, 1e-4]}),
        "BinaryState.synchronous": (call(BinaryState.synchronous, system=system, separation=1200 * u.m,
                                         primary_spin=7e-4 * u.rad / u.s),
                                    {"separation": 1200.0, "primary_spin": 7e-4, "speed": 0.1, "libration": 0.01}),
        "BinaryState.with_velocity_change": (call(BinaryState(**binary).with_velocity_change,
                                                  delta_v=[0, -2.7e-3, 0] * u.m / u.s), {"delta_v": [0, -2.7e-3, 0]}),
        "BinarySystem.circular_speed": (call(system.circular_speed, separation=1200 * u.m), {"separation": 1200.0}),
        "HeliocentricOrbit": (call(HeliocentricOrbit, semi_major_axis=1.64 * u.au),
                              {"semi_major_axis": 1.64, "inclination": 3.4, "node": 73.0, "argument_of_pericentre": 319.0,
                               "mean_anomaly": 10.0}),
        "momentum_impulse": (call(momentum_impulse, impactor_mass=579.4 * u.kg, impactor_velocity=[0, -6144.9, 0] * u.m / u.s,
                                  beta=3.61, target_mass=4.3e9 * u.kg),
                             {"impactor_mass": 579.4, "impactor_velocity": [0, -6144.9, 0], "target_mass": 4.3e9}),
        "Figure.sphere": (call(Figure.sphere, name="A", radius=300 * u.m, density=2000 * u.kg / u.m**3),
                          {"radius": 300.0, "density": 2000.0}),
        "Figure.ellipsoid": (call(Figure.ellipsoid, name="B", semi_axes=[100, 80, 60] * u.m,
                                  density=2000 * u.kg / u.m**3), {"semi_axes": [100, 80, 60], "density": 2000.0}),
        "Figure.from_shape": (call(Figure.from_shape, name="C", shape=shape, density=2000 * u.kg / u.m**3),
                              {"density": 2000.0, "mass": {"mass": 5e12, "density": None}}),
        "Figure.from_inertia": (call(Figure.from_inertia, name="D", mass=4.3e9 * u.kg,
                                     inertia=[2.1e12, 3.2e12, 3.9e12] * u.kg * u.m**2, circumscribing_radius=103 * u.m),
                                {"mass": 4.3e9, "inertia": [2.1e12, 3.2e12, 3.9e12], "circumscribing_radius": 103.0}),
        # fits
        "AttitudeObservation": (call(AttitudeObservation, epoch=EPOCH, quaternion=[1.0, 0, 0, 0], sigma=2 * u.deg),
                                {"sigma": 2.0}),
        "AxisObservation": (call(AxisObservation, epoch=EPOCH, body_axis=[0, 0, 1.0], direction=[0, 0, 1.0],
                                 sigma=2 * u.deg), {"sigma": 2.0}),
        "PeriodObservation": (call(PeriodObservation, epoch=EPOCH, kind="rotation", period=5.41 * u.day,
                                   sigma=0.01 * u.day), {"period": 5.41, "sigma": 0.01}),
        "SpinRateObservation": (call(SpinRateObservation, epoch=EPOCH, rate=105 * u.deg / u.day,
                                     sigma=0.5 * u.deg / u.day), {"rate": 105.0, "sigma": 0.5}),
        # published bodies
        "didymos_state": (call(didymos_state, libration=0.01 * u.rad), {"libration": 0.01}),
        "dart_system": (call(dart_system), {"separation": 1.206, "period": 11.92, "didymos_radii": [394.0, 290.0],
                                            "dimorphos_extents": [177.0, 174.0, 116.0], "density": 2.4}),
        "dart_state": (call(dart_state, system=dart), {"separation": 1.206, "libration": 0.01}),
        "along_track": (call(along_track, state=dart_state(dart), delta_v=-2.63 * u.mm / u.s), {"delta_v": -2.63}),
        # effects
        "yarkovsky_drift": (
            call(yarkovsky_drift, radius=250 * u.m, density=2000 * u.kg / u.m**3,
                 heat_capacity=680 * u.J / (u.kg * u.K), rotation_period=5 * u.h, obliquity=30 * u.deg,
                 semi_major_axis=1 * u.au, thermal_inertia=300 * u.J / (u.m**2 * u.K * u.s**0.5)),
            {"radius": 250.0, "density": 2000.0, "heat_capacity": 680.0, "rotation_period": 5.0, "obliquity": 30.0,
             "semi_major_axis": 1.0, "thermal_inertia": 300.0, "spin_longitude": 0.0,
             "conductivity": {"conductivity": 0.01, "thermal_inertia": None}}),
    }


def _walked():
    """(qualified name, callable) of every function, constructor and method the scope exports, records aside."""
    seen, found = set(), []
    for module_name in SCOPE:
        module = importlib.import_module(module_name)
        names = getattr(module, "__all__", None)
        if names is None:
            names = sorted(n for n in _defined_names(PUBLIC_MODULES[module_name]) if not n.startswith("_"))
        for name in names:
            obj = getattr(module, name)
            if id(obj) in seen or not callable(obj) or (inspect.isclass(obj) and issubclass(obj, BaseException)):
                continue
            seen.add(id(obj))
            if name in RECORDS:
                continue
            if not inspect.isclass(obj):
                found.append((name, obj))
                continue
            found.append((name, obj))
            for attribute, value in vars(obj).items():
                if attribute.startswith("_") or attribute in CORE_HOOKS:
                    continue
                function = value.__func__ if isinstance(value, (classmethod, staticmethod)) else value
                if inspect.isfunction(function):
                    found.append((f"{name}.{attribute}", function))
    return found


def _parameters(function):
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):
        return []
    return [p for p in signature.parameters.values()
            if p.name not in ("self", "cls") and not p.name.startswith("_")
            and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def test_every_parameter_of_the_public_api_is_classified():
    calls = _calls()
    unclassified = []
    for qualified, function in _walked():
        short = qualified.split(".")[-1]
        dimensional = set(calls.get(qualified, (None, {}))[1])
        for parameter in _parameters(function):
            name = parameter.name
            if (name in dimensional or name in NOT_DIMENSIONAL_ANYWHERE or UNIT_SUFFIX.search(name)
                    or name in NOT_DIMENSIONAL_IN.get(qualified, ()) or name in NOT_DIMENSIONAL_IN.get(short, ())):
                continue
            unclassified.append(f"{qualified}({name})")
    assert unclassified == [], (
        "parameters of the public API that are neither dimensional (DIMENSIONAL, with a call) nor listed as "
        "dimensionless (NOT_DIMENSIONAL_*) in tests/test_units_never_guessed.py; a dimensional one takes a "
        "Quantity through spinorbit.quantities.value_in:\n" + "\n".join(unclassified))


def _cases():
    return [(qualified, parameter, bare) for qualified, (_, bad) in _calls().items() for parameter, bare in bad.items()]


@pytest.mark.parametrize("qualified, parameter, bare", _cases(), ids=[f"{q}-{p}" for q, p, _ in _cases()])
def test_a_bare_number_for_a_dimensional_parameter_is_refused_with_a_hint(qualified, parameter, bare):
    call, _ = _calls()[qualified]
    with pytest.raises(QuantityInputError) as refused:  # a dict: the bare number with the alternative it replaces
        call(**(bare if isinstance(bare, dict) else {parameter: bare}))
    message = str(refused.value)
    assert parameter in message and "bare" in message and "u." in message, message
    assert "\n" not in message, message  # one line


@pytest.mark.parametrize("qualified", sorted(_calls()))
def test_each_call_of_the_walk_works_with_its_quantities(qualified):
    call, _ = _calls()[qualified]
    call()  # the valid call the refusals start from: a refusal above is the bare number's, nothing else's
