"""Rigid-body rotation coupled to REBOUND orbits (spinorbit.coupling): conservation, modes, I/O, errors.

Small artificial system: a triaxial body (mass 0.3) on an eccentric, inclined orbit (a = 3, e = 0.2)
around a point mass 1 (G = 1), no extra forces, so that the total energy (orbits + spin − figure
potential) and the total angular momentum (orbital + spin) are exact invariants of the coupled flow.
"""

import numpy as np
import pytest
import rebound

from spinorbit.core.model.gravity_field import make_body
from spinorbit.coupling.rebound import (
    ForceInstallError,
    MissingBodyError,
    RotationCallbackError,
    install_extra_forces,
    set_nongravitational,
)
from spinorbit.coupling.rigid_body import CoupledRigidBody, RestoreError

#: BS tolerance of the artificial runs: the tightest that still keeps steps well above roundoff.
BS_TOLERANCE = 1e-13
#: Orbital period of the test orbit (a = 3, G(M + m) = 1.3).
ORBIT_PERIOD = 2.0 * np.pi * np.sqrt(27.0 / 1.3)
#: Relative energy and angular-momentum drift allowed over 10 orbits. Measured 4e-13 (energy) and
#: 6e-14 (angular momentum) with BS at 1e-13; 100× margin for other platforms. Reading the ODE's
#: start-of-step state ``y`` instead of the stage ``y1`` in the back-reaction gives ~1e-3 (shared note).
CONSERVATION_TOLERANCE = 1e-10


def _system(coupled=True, moments=(0.02, 0.025, 0.03), mass=0.3, radius=0.4, extra=False):
    sim = rebound.Simulation()
    sim.integrator = "bs"
    sim.integrator.eps_abs = BS_TOLERANCE
    sim.integrator.eps_rel = BS_TOLERANCE
    sim.add(m=1.0, name="Planet")
    sim.add(m=mass, a=3.0, e=0.2, inc=0.3, name="Body")
    sim.move_to_com()
    sim.exact_finish_time = 1
    figure = make_body(moments, mass=mass, reference_radius=radius,
                       # C33 = 1e-3, C32 = 2e-3: degree 3 exercises the Stokes torque and reaction
                       stokes_c=np.diag([0, 0, 0, 1e-3]) + np.eye(4, k=-1) * 2e-3, stokes_s=None)
    state = [1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 1.0]  # spin mostly about C, with some wobble
    return CoupledRigidBody(sim, "Body", figure, state, coupled=coupled)


def test_coupled_mode_conserves_energy_and_angular_momentum():
    body = _system()
    energy0, momentum0 = body.total_energy(), body.total_angular_momentum()
    spin0 = body.omega.copy()
    body.integrate(10 * ORBIT_PERIOD)
    energy_error = abs(body.total_energy() / energy0 - 1.0)
    momentum_error = np.linalg.norm(body.total_angular_momentum() - momentum0) / np.linalg.norm(momentum0)
    assert energy_error < CONSERVATION_TOLERANCE
    assert momentum_error < CONSERVATION_TOLERANCE
    # The figure really exchanged angular momentum with the orbit (the test is not vacuous).
    assert np.linalg.norm(body.omega - spin0) > 1e-3


def test_one_way_mode_does_not_conserve_when_the_reaction_matters():
    """One-way drops the reaction: the invariants drift far above the coupled mode's tolerance."""
    body = _system(coupled=False)
    momentum0 = body.total_angular_momentum()
    body.integrate(10 * ORBIT_PERIOD)
    drift = np.linalg.norm(body.total_angular_momentum() - momentum0) / np.linalg.norm(momentum0)
    assert drift > 1e3 * CONSERVATION_TOLERANCE


def test_one_way_equals_coupled_when_the_reaction_is_negligible():
    """A tiny figure (I/(m a²) ~ 1e-9) barely perturbs the orbit: both modes agree to ~that level."""
    small = dict(moments=(2e-10, 2.5e-10, 3e-10), radius=4e-5)
    coupled, one_way = _system(True, **small), _system(False, **small)
    for body in (coupled, one_way):
        body.integrate(3 * ORBIT_PERIOD)
    # Difference set by the figure/monopole force ratio (~1e-9) times the orbit's phase sensitivity;
    # measured 1.4e-10 (rotation state) and 2.4e-9 (position): bounds 40× above the larger.
    assert np.max(np.abs(coupled.state - one_way.state)) < 1e-7
    position = [np.array(b.sim.particles["Body"].xyz) for b in (coupled, one_way)]
    assert np.linalg.norm(position[0] - position[1]) < 1e-7


def test_save_and_restore_continue_bit_for_bit(tmp_path):
    path = tmp_path / "run.ckpt"
    original = _system()
    original.integrate(2.0 * ORBIT_PERIOD)
    original.save(path)
    original.integrate(4.0 * ORBIT_PERIOD)
    restored = CoupledRigidBody.restore(path)
    assert restored.sim.t == 2.0 * ORBIT_PERIOD
    restored.integrate(4.0 * ORBIT_PERIOD)
    assert np.array_equal(restored.state, original.state)
    for name in ("Planet", "Body"):
        a, b = original.sim.particles[name], restored.sim.particles[name]
        assert a.xyz == b.xyz and a.vxyz == b.vxyz
    assert [p.name for p in tmp_path.iterdir()] == ["run.ckpt"]  # no temporary file left


def test_restore_refuses_other_files(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, x=np.zeros(3))
    with pytest.raises(RestoreError, match="not a spinorbit checkpoint"):
        CoupledRigidBody.restore(path)


def test_callback_error_stops_the_run_and_is_reported():
    body = _system()
    body.sim.add(m=1e-3, a=10.0, name="Intruder")  # particle indices in the cfuncs are now stale
    with pytest.raises(RotationCallbackError, match="number of particles changed"):
        body.integrate(ORBIT_PERIOD)
    assert body.sim.t < ORBIT_PERIOD  # stopped early, not run to the end with garbage


def test_nonfinite_rotation_state_is_reported():
    body = _system()
    body.hooks.state = [np.nan, 0, 0, 0, 0, 0, 1.0]
    with pytest.raises(RotationCallbackError, match="NaN or infinite"):
        body.integrate(ORBIT_PERIOD)


def test_missing_body_is_named():
    sim = rebound.Simulation()
    sim.integrator = "bs"
    sim.add(m=1.0, name="Planet")
    sim.add(m=0.3, a=3.0, name="Body")
    figure = make_body((1, 2, 3))
    with pytest.raises(MissingBodyError, match="'Moon'.*'Planet', 'Body'"):
        CoupledRigidBody(sim, "Moon", figure, [1, 0, 0, 0, 0, 0, 1])
    with pytest.raises(MissingBodyError, match="'Earth'"):
        CoupledRigidBody(sim, "Body", figure, [1, 0, 0, 0, 0, 0, 1], perturbers=["Earth"])


def test_refuses_integrators_that_decouple_user_odes():
    sim = rebound.Simulation()
    sim.add(m=1.0, name="Planet")
    sim.add(m=0.3, a=3.0, name="Body")
    with pytest.raises(ForceInstallError, match="'bs'"):
        CoupledRigidBody(sim, "Body", make_body((1, 2, 3)), [1, 0, 0, 0, 0, 0, 1])


def _sun_earth_moon(moon_a):
    """Sun, Earth and Moon (au, day, Msun) under BS, with the Moon at ``moon_a`` au from Earth."""
    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.integrator = "bs"
    sim.add(m=1.0, name="Sun")
    sim.add(m=3e-6, a=1.0, name="Earth")
    sim.add(m=3.7e-8, a=moon_a, primary=sim.particles[1], name="Moon")
    return sim


def test_refuses_a_second_body_and_folds_in_earlier_extra_forces():
    sim = _sun_earth_moon(1.0026)
    install_extra_forces(sim, earth_j2=True, gr=True)
    body = CoupledRigidBody(sim, "Moon", make_body((1e-20, 1.1e-20, 1.2e-20)), [1, 0, 0, 0, 0, 0, 0.23])
    assert body.hooks.extra is not None and body.hooks.extra.earth_j2 and body.hooks.extra.gr
    with pytest.raises(ForceInstallError, match="already attached"):
        CoupledRigidBody(sim, "Earth", make_body((1, 2, 3)), [1, 0, 0, 0, 0, 0, 1])


def test_ias15_pseudo_particle_route_conserves_and_agrees_with_bs():
    """The alternative route (measured in benchmarks/bench_coupling_routes.py) stays correct."""
    from spinorbit.coupling.rebound import attach_rotation_ias15

    reference = _system()
    reference.integrate(2 * ORBIT_PERIOD)
    sim = rebound.Simulation()
    sim.integrator = "ias15"
    sim.add(m=1.0, name="Planet")
    sim.add(m=0.3, a=3.0, e=0.2, inc=0.3, name="Body")
    sim.move_to_com()
    sim.exact_finish_time = 1
    hooks = attach_rotation_ias15(sim, "Body", ["Planet"], reference.figure, [1.0, 0, 0, 0, 0.1, 0.2, 1.0])
    sim.integrate(2 * ORBIT_PERIOD)
    hooks.raise_if_failed()
    quaternion = hooks.state[:4] / np.linalg.norm(hooks.state[:4])
    # Two 1e-13-class integrators over 2 orbits of a strongly torqued body: measured 7e-14 (q) and
    # 1.5e-14 (ω); 1e-9 leaves room for other platforms and step sequences.
    assert np.max(np.abs(np.abs(quaternion) - np.abs(reference.quaternion))) < 1e-9
    assert np.max(np.abs(hooks.state[4:] - reference.omega)) < 1e-9


def test_attaching_a_body_keeps_earlier_non_gravitational_forces():
    # A transverse 1e-10 au/day² on the Moon, set before the body is attached: the combined force must
    # carry it (it was dropped when only J2/EIH flags were folded in). Over 10 d it moves the Moon by
    # ~a t² = 1e-8 au; BS at 1e-13 is reproducible to ~1e-15 au.
    positions = []
    for a2 in (0.0, 1e-10):
        sim = rebound.Simulation()
        sim.units = ("AU", "day", "Msun")
        sim.integrator = "bs"
        sim.integrator.eps_abs = sim.integrator.eps_rel = BS_TOLERANCE
        sim.add(m=1.0, name="Sun")
        sim.add(m=3e-6, a=1.0, name="Earth")
        sim.add(m=3.7e-8, a=0.00257, primary=sim.particles[1], name="Moon")
        install_extra_forces(sim, earth_j2=False, gr=False)
        set_nongravitational(sim, "Moon", 0.0, a2)
        body = CoupledRigidBody(sim, "Moon", make_body((1e-20, 1.1e-20, 1.2e-20)), [1, 0, 0, 0, 0, 0, 0.23])
        body.integrate(10.0)
        positions.append(np.array(sim.particles["Moon"].xyz))
    assert np.linalg.norm(positions[1] - positions[0]) > 1e-9


def test_attach_refuses_forces_the_earlier_block_does_not_have():
    """Attaching folds an earlier install_extra_forces block unchanged: asking the constructor for J2,
    EIH or another pole on top of it would be silently ignored, so it raises instead."""
    sim = _sun_earth_moon(0.00257)
    install_extra_forces(sim, earth_j2=True, gr=False, earth_pole=(0.0, 0.6, 0.8))
    figure, state = make_body((1e-20, 1.1e-20, 1.2e-20)), [1, 0, 0, 0, 0, 0, 0.23]
    with pytest.raises(ForceInstallError, match="without gr; attaching folds in that block unchanged"):
        CoupledRigidBody(sim, "Moon", figure, state, gr=True)
    with pytest.raises(ForceInstallError, match=r"without earth_pole=\(0.0, 0.0, 1.0\)"):
        CoupledRigidBody(sim, "Moon", figure, state, earth_j2=True)
    body = CoupledRigidBody(sim, "Moon", figure, state, earth_j2=True, earth_pole=(0.0, 0.6, 0.8))
    assert body.earth_j2 and not body.gr


def test_bs_flag_restore_is_refused_for_other_integrators():
    body = _system()
    body.sim.integrator = "ias15"
    with pytest.raises(ForceInstallError, match="needs the 'bs' integrator, got"):
        body.hooks.resume_bs_controller(body.sim, 0)
