"""BS + user ODE vs IAS15 + pseudo-particles for the coupled lunar rotation (docs/coupling.md).

Runs the Moon from DE421 at J2000 for one year both ways (same forces, same figure, same torque
kernel), prints wall time, the attitude difference against DE421 and between the routes, and the
Moon's position difference between the routes. Also the conservation of the IAS15 route on the
artificial system of tests/test_coupling.py. Usage: python benchmarks/bench_coupling_routes.py
(``--quick``: 10 days and one orbit of the artificial system, a smoke run). Prints only.
"""

import sys
import time

import numpy as np
import rebound
from astropy.time import Time

from spinorbit.core.model.gravity_field import make_body
from spinorbit.core.dynamics.equations import inertial_angular_momentum
from spinorbit.coupling.moon import ARCSEC_PER_RAD, moon_at_de421, moon_figure
from spinorbit.coupling.rebound import attach_rotation_ias15, simulation_from_de421
from spinorbit.ephemeris import moon_orientation_raw

YEAR = 365.25


def angle_arcsec(q1, q2):
    q1, q2 = q1 / np.linalg.norm(q1), q2 / np.linalg.norm(q2)
    # 2 atan2(|vec(conj(q1) ⊗ q2)|, |q1·q2|): accurate for tiny angles, unlike arccos
    vec = q1[0] * q2[1:] - q2[0] * q1[1:] - np.cross(q1[1:], q2[1:])
    return 2.0 * np.arctan2(np.linalg.norm(vec), abs(float(np.dot(q1, q2)))) * ARCSEC_PER_RAD


def ias15_moon(model):
    sim = simulation_from_de421(Time(2451545.0, format="jd", scale="tdb"), integrator="ias15")
    quaternion, omega = moon_orientation_raw(0.0, 0.0)
    moon = sim.particles["Moon"]
    perturbers = [p.name for p in sim.particles if p.name != "Moon"]
    hooks = attach_rotation_ias15(sim, "Moon", perturbers, moon_figure(moon.m, model),
                                  np.concatenate([quaternion, omega]), earth_j2=True, gr=True)
    return sim, hooks


#: ``--quick`` (benchmarks/run_all.py's smoke run): days of the Moon runs, orbits of the artificial system.
QUICK_SPAN_DAYS, QUICK_ORBITS = 10.0, 1


def main():
    global YEAR
    orbits = 10
    if "--quick" in sys.argv[1:]:
        YEAR, orbits = QUICK_SPAN_DAYS, QUICK_ORBITS
    for model in ("rigid", "core-corrected"):
        bs = moon_at_de421(model=model, full_field_perturbers=None)  # same field for every perturber
        start = time.perf_counter()
        bs.integrate(bs.sim.t + YEAR)
        bs_wall = time.perf_counter() - start
        sim, hooks = ias15_moon(model)
        start = time.perf_counter()
        sim.integrate(sim.t + YEAR)
        ias_wall = time.perf_counter() - start
        hooks.raise_if_failed()
        reference, _ = moon_orientation_raw(np.round(YEAR), YEAR - np.round(YEAR))
        moon_bs = np.array(bs.sim.particles["Moon"].xyz) - np.array(bs.sim.particles["Earth"].xyz)
        moon_ias = np.array(sim.particles["Moon"].xyz) - np.array(sim.particles["Earth"].xyz)
        print(f"{model:15s} BS: {bs_wall:.3f} s, {angle_arcsec(bs.quaternion, reference):.4f}\" vs DE421 at 1 yr | "
              f"IAS15: {ias_wall:.3f} s, {angle_arcsec(hooks.state[:4], reference):.4f}\" | "
              f"routes differ {angle_arcsec(bs.quaternion, hooks.state[:4]):.2e}\", "
              f"geocentric Moon {np.linalg.norm(moon_bs - moon_ias) * 1.495978707e11:.2f} m")

    sim = rebound.Simulation()
    sim.integrator = "ias15"
    sim.add(m=1.0, name="Planet")
    sim.add(m=0.3, a=3.0, e=0.2, inc=0.3, name="Body")
    sim.move_to_com()
    figure = make_body((0.02, 0.025, 0.03), mass=0.3, reference_radius=0.4,
                       stokes_c=np.diag([0, 0, 0, 1e-3]) + np.eye(4, k=-1) * 2e-3)
    hooks = attach_rotation_ias15(sim, "Body", ["Planet"], figure, [1, 0, 0, 0, 0.1, 0.2, 1.0])

    def invariants():
        y = hooks.state
        y[:4] /= np.linalg.norm(y[:4])
        from spinorbit.coupling.rigid_body import CoupledRigidBody  # noqa: F401  (same formulas)
        from spinorbit.core.dynamics.equations import body_frame_position, kinetic_energy
        from spinorbit.core.model.gravity_field import figure_force_function_and_gradient
        p, b = sim.particles["Planet"], sim.particles["Body"]
        r = body_frame_position(y[:4], np.array(p.xyz) - np.array(b.xyz))
        u, _ = figure_force_function_and_gradient(r, sim.G * p.m, figure)
        u -= sim.G * p.m * b.m / np.linalg.norm(r)
        orbital_l = sum(q.m * np.cross(q.xyz, q.vxyz) for q in (p, b))
        return sim.energy() + kinetic_energy(y, figure) - u, orbital_l + inertial_angular_momentum(y, figure)

    e0, l0 = invariants()
    sim.integrate(orbits * 2 * np.pi * np.sqrt(27 / 1.3))
    e1, l1 = invariants()
    print(f"IAS15 route, artificial system, {orbits} orbits: relative energy error {abs(e1 / e0 - 1):.1e}, "
          f"angular momentum {np.linalg.norm(l1 - l0) / np.linalg.norm(l0):.1e}")


if __name__ == "__main__":
    main()
