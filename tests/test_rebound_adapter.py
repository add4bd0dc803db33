"""spinorbit.coupling.rebound: offline DE421 simulations, raw-pointer forces, perturbers."""

import numpy as np
import pytest
import rebound
from _offline import no_network  # noqa: F401  (autouse socket guard)
from astropy.time import Time

from spinorbit.coupling.rebound import (
    DEFAULT_BODIES,
    ForceInstallError,
    MissingBodyError,
    body_index,
    install_extra_forces,
    perturber_positions,
    set_nongravitational,
    simulation_from_de421,
)
from spinorbit.ephemeris import barycentric_state_au, barycentric_state_km, de421_constants

J2000 = Time(2451545.0, format="jd", scale="tdb")
ONE_YEAR_DAYS = 365.25

#: Moon geocentric position after one year from J2000, 11 bodies + EIH + Earth J2, vs DE421.
#: Measured 497.36 m (REBOUNDx gr_full + gravitational_harmonics on the same sim: 497.35 m; the
#: shared note measured 564 m with its set-up). What is missing is DE421's lunar figure (degree 2–4,
#: worth ≈ 500 m per the note), tides and asteroids. 600 m leaves room for platform rounding, and
#: fails if either force breaks (without J2: 23 km; without GR: 3.2 km).
MOON_ONE_YEAR_TOLERANCE_M = 600.0
#: Same physics as REBOUNDx's forces on the same initial conditions: only integration noise differs.
REBOUNDX_AGREEMENT_M = 0.5


def _moon_error_m(sim, t_days):
    au_km = de421_constants().au_km
    particles = sim.particles
    geocentric = np.array(particles["Moon"].xyz) - np.array(particles["Earth"].xyz)
    moon, _ = barycentric_state_km("moon", t_days)
    earth, _ = barycentric_state_km("earth", t_days)
    return np.linalg.norm(geocentric * au_km - (moon - earth)) * 1e3


def test_simulation_is_de421_at_the_epoch():
    time = Time("2010-03-04T05:06:07", scale="tt")
    sim = simulation_from_de421(time)
    assert sim.N == len(DEFAULT_BODIES)
    assert sim.exact_finish_time == 1
    assert sim.G == pytest.approx(de421_constants().gm["sun"], rel=1e-14)
    assert sim.t == pytest.approx((time.tdb.jd1 - 2451545.0) + time.tdb.jd2, abs=1e-11)
    assert sim.particles["Moon"].m * sim.G == pytest.approx(de421_constants().gm["moon"], rel=1e-14)
    # Moving to the centre of mass shifts every body by the same vector: relative positions stay.
    moon, _ = barycentric_state_au("moon", sim.t)
    earth, _ = barycentric_state_au("earth", sim.t)
    geocentric = np.array(sim.particles["Moon"].xyz) - np.array(sim.particles["Earth"].xyz)
    np.testing.assert_allclose(geocentric, moon - earth, atol=1e-14)


@pytest.mark.validation
def test_moon_after_one_year_with_j2_and_eih():
    sim = simulation_from_de421(J2000)
    install_extra_forces(sim, earth_j2=True, gr=True)
    sim.integrate(ONE_YEAR_DAYS)
    assert sim.t == ONE_YEAR_DAYS  # exact_finish_time
    assert _moon_error_m(sim, ONE_YEAR_DAYS) < MOON_ONE_YEAR_TOLERANCE_M


@pytest.mark.validation
def test_extra_forces_match_reboundx():
    reboundx = pytest.importorskip("reboundx")
    c = de421_constants()
    ours = simulation_from_de421(J2000)
    install_extra_forces(ours)
    ours.integrate(ONE_YEAR_DAYS)

    theirs = simulation_from_de421(J2000)
    extras = reboundx.Extras(theirs)
    gr = extras.load_force("gr_full")
    extras.add_force(gr)
    gr.params["c"] = c.c_km_s * 86400.0 / c.au_km
    harmonics = extras.load_force("gravitational_harmonics")
    extras.add_force(harmonics)
    theirs.particles["Earth"].params["J2"] = c.earth_j2
    theirs.particles["Earth"].params["R_eq"] = c.earth_radius_km / c.au_km
    theirs.integrate(ONE_YEAR_DAYS)
    assert abs(_moon_error_m(ours, ONE_YEAR_DAYS) - _moon_error_m(theirs, ONE_YEAR_DAYS)) < REBOUNDX_AGREEMENT_M
    difference = np.array(ours.particles["Moon"].xyz) - np.array(theirs.particles["Moon"].xyz)
    assert np.linalg.norm(difference) * c.au_km * 1e3 < REBOUNDX_AGREEMENT_M


def test_each_force_moves_the_moon_the_right_way():
    errors = {}
    for j2, gr in [(False, False), (True, True)]:
        sim = simulation_from_de421(J2000)
        if j2 or gr:
            install_extra_forces(sim, earth_j2=j2, gr=gr)
        sim.integrate(90.0)
        errors[(j2, gr)] = _moon_error_m(sim, 90.0)
    assert errors[(True, True)] < errors[(False, False)] / 10.0


def test_perturber_positions_are_body_centric():
    sim = simulation_from_de421(J2000)
    positions, gm, names = perturber_positions(sim, "moon")
    assert names == tuple(name.capitalize() for name in DEFAULT_BODIES if name != "moon")
    assert positions.shape == (len(DEFAULT_BODIES) - 1, 3) and gm.shape == (len(DEFAULT_BODIES) - 1,)
    earth_row = names.index("Earth")
    expected = np.array(sim.particles["Earth"].xyz) - np.array(sim.particles["Moon"].xyz)
    np.testing.assert_array_equal(positions[earth_row], expected)
    assert gm[earth_row] == pytest.approx(de421_constants().gm["earth"], rel=1e-14)
    # A chosen subset, in the order asked; and it follows the running simulation.
    sim.integrate(1.0)
    positions, _, names = perturber_positions(sim, "Moon", perturbers=["Sun", "earth"])
    assert names == ("Sun", "Earth")
    expected = np.array(sim.particles["Sun"].xyz) - np.array(sim.particles["Moon"].xyz)
    np.testing.assert_array_equal(positions[0], expected)


def test_missing_body_is_named():
    sim = simulation_from_de421(J2000, bodies=("sun", "jupiter"))
    with pytest.raises(MissingBodyError, match="no particle named 'Moon'.*'Sun', 'Jupiter'"):
        perturber_positions(sim, "Moon")
    with pytest.raises(MissingBodyError, match="'earth'"):
        install_extra_forces(sim)
    assert body_index(sim, "JUPITER") == 1


def test_double_install_and_reboundx_are_refused():
    sim = simulation_from_de421(J2000, bodies=("sun", "earth", "moon"))
    install_extra_forces(sim)
    with pytest.raises(ForceInstallError, match="already installed"):
        install_extra_forces(sim)
    reboundx = pytest.importorskip("reboundx")
    other = simulation_from_de421(J2000, bodies=("sun", "earth", "moon"))
    reboundx.Extras(other)
    with pytest.raises(ForceInstallError, match="REBOUNDx"):
        install_extra_forces(other)


def test_bad_inputs():
    with pytest.raises(TypeError, match="scalar Time"):
        simulation_from_de421(Time([2451545.0, 2451546.0], format="jd", scale="tdb"))
    with pytest.raises(ValueError, match="unit 3-vector"):
        install_extra_forces(simulation_from_de421(J2000, bodies=("earth", "moon")), earth_pole=(0, 0, 2))


def test_forces_survive_garbage_collection():
    # The cfunc pointer and its parameters must live as long as the simulation, not as the handle.
    import gc

    sim = simulation_from_de421(J2000, bodies=("sun", "earth", "moon"))
    install_extra_forces(sim)  # handle discarded on purpose
    gc.collect()
    sim.integrate(30.0)
    assert np.all(np.isfinite(sim.particles["Moon"].xyz))
    assert isinstance(sim, rebound.Simulation)


def _sun_and_circular_body(gm_effective=1.0):
    """Sun (GM = 1, at rest) and a massless body on a circular 1 au orbit for the given effective GM."""
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0, name="Sun")
    sim.add(m=0.0, x=1.0, vy=np.sqrt(gm_effective), name="Body")
    sim.integrator = "ias15"
    install_extra_forces(sim, earth_j2=False, gr=False)
    return sim


def test_nongravitational_terms_obey_the_gauss_equations():
    """Each of A1, A2, A3 against what it must do on a circular orbit at r0 = 1 au (GM = 1).

    - A1 (radial, ∝ 1/r²) is a reduction of GM by A1: a circular orbit for GM − A1 stays at r = 1
      (without the force it would not: 5e-4 of GM gives an eccentricity of 5e-4).
    - A2 (transverse): da/dt = 2 A2 / n (Gauss, circular orbit), so Δa = 2 A2 T over T with n = 1.
      Second-order terms are (A2 T)² ~ 1e-10 relative to Δa ≈ 2e-7: tolerance 1e-4 relative.
    - A3 (normal): z'' = −z + A3 (n = 1) gives z = A3 (1 − cos t), largest 2 A3 at half an orbit;
      checked as A3/2 < max|z| ≤ 2 A3 (1 + 1e-3) over one orbit (1e-3: A3² and sampling terms).
    """
    a1 = 5e-4
    sim = _sun_and_circular_body(gm_effective=1.0 - a1)
    set_nongravitational(sim, "Body", a1)
    radii = []
    for t in np.linspace(0.0, 20.0, 81):
        sim.integrate(t)
        radii.append(np.linalg.norm(sim.particles["Body"].xyz))
    assert np.max(np.abs(np.array(radii) - 1.0)) < 1e-12

    a2, span = 1e-8, 10.0
    sim = _sun_and_circular_body()
    set_nongravitational(sim, "Body", 0.0, a2)
    sim.integrate(span)
    assert sim.particles["Body"].orbit(primary=sim.particles["Sun"]).a - 1.0 == pytest.approx(
        2.0 * a2 * span, rel=1e-4)

    a3 = 1e-6
    sim = _sun_and_circular_body()
    set_nongravitational(sim, "Body", 0.0, 0.0, a3)
    z = []
    for t in np.linspace(0.0, 2.0 * np.pi, 64):
        sim.integrate(t)
        z.append(sim.particles["Body"].z)
    assert 0.5 * a3 < np.max(np.abs(z)) <= 2.0 * a3 * (1.0 + 1e-3)


def test_nongravitational_needs_installed_forces_and_a_real_body():
    sim = rebound.Simulation()
    sim.add(m=1.0, name="Sun")
    sim.add(m=0.0, x=1.0, vy=1.0, name="Body")
    with pytest.raises(ForceInstallError, match="install_extra_forces"):
        set_nongravitational(sim, "Body", 1e-12)
    install_extra_forces(sim, earth_j2=False, gr=False)
    with pytest.raises(MissingBodyError, match="Apophis"):
        set_nongravitational(sim, "Apophis", 1e-12)
    with pytest.raises(ValueError, match="finite"):
        set_nongravitational(sim, "Body", float("nan"))


def test_reinstalled_forces_carry_every_parameter():
    """A rebuilt copy (the one-way sampler's route) integrates bit-for-bit like the original."""
    from spinorbit.coupling.rebound import reinstall_extra_forces

    original = _sun_and_circular_body()
    set_nongravitational(original, "Body", 1e-6, -3e-7, 2e-7)
    copy = rebound.Simulation()
    copy.G = 1.0
    for p in original.particles:
        copy.add(m=p.m, x=p.x, y=p.y, z=p.z, vx=p.vx, vy=p.vy, vz=p.vz, name="Sun" if p.m else "Body")
    copy.integrator = "ias15"
    reinstall_extra_forces(copy, original._afp)
    for sim in (original, copy):
        sim.integrate(5.0)
    assert original.particles["Body"].xyz == copy.particles["Body"].xyz


# ------------------------------------------------------------------------------------- rebuilt copies
def _three_bodies(integrator, **settings):
    """Sun, Earth-like and an eccentric body (au, day, Msun), EIH and a non-gravitational term on."""
    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.integrator = integrator
    for name, value in settings.items():
        setattr(sim.integrator, name, value)
    sim.add(m=1.0, name="Sun")
    sim.add(m=3e-6, a=1.0, e=0.0167, name="Earth")
    sim.add(m=0.0, a=1.3, e=0.4, inc=0.2, name="Body")
    sim.move_to_com()
    install_extra_forces(sim, earth_j2=True, gr=True)
    set_nongravitational(sim, "Body", 1e-9, -2e-10, 5e-11)
    return sim


@pytest.mark.parametrize("integrator, settings, warm", [
    ("bs", {"eps_abs": 1e-11, "eps_rel": 1e-10, "min_dt": 1e-4}, False),  # BS defaults: 1e-8, 1e-8, 0
    ("ias15", {"epsilon": 1e-5, "adaptive_mode": "global", "min_dt": 1e-4}, False),  # 1e-9, PRS23, 0
    ("ias15", {"epsilon": 1e-5, "adaptive_mode": "global", "min_dt": 1e-4}, True),
])
def test_a_rebuilt_copy_integrates_bit_for_bit_like_the_original(integrator, settings, warm):
    """The one-way sampler's copies (``rebound.SimulationSnapshot``) keep every integrator setting (and state).

    The old copy (particles, G, integrator name) ran BS at the default eps 1e-8 and IAS15 at epsilon
    1e-9. IAS15 is also copied mid-run (dt and its predictor are in REBOUND's binary). BS mid-run is
    not: rebound 5.2.2 keeps its internal N-body ODE outside the binary, and creating it again at the
    copy's first step resets ``first_or_last_step`` (also with ``sim.copy()``); copied at day 10.3,
    measured 3.5e-14 au apart at day 40 (docs/coupling.md).
    """
    from spinorbit.coupling.rebound import SimulationSnapshot

    original = _three_bodies(integrator, **settings)
    if warm:
        original.integrate(10.3)
    copy = SimulationSnapshot.of(original).build()
    for name, value in settings.items():
        assert getattr(copy.integrator, name) == getattr(original.integrator, name)
    for t in (11.0, 17.5, 40.0):
        original.integrate(t)
        copy.integrate(t)
        for name in ("Sun", "Earth", "Body"):
            assert copy.particles[name].xyz == original.particles[name].xyz, (t, name)
    assert copy.steps_done == original.steps_done


def test_a_copy_keeps_the_forces_folded_into_a_rigid_body_and_refuses_foreign_ones():
    """A simulation with a body attached holds its earlier extra forces in the body's combined force:
    a copy must still carry them (the old copy saw no ExtraForces handle and dropped them)."""
    from spinorbit.core.model.gravity_field import make_body
    from spinorbit.coupling.rebound import SimulationSnapshot
    from spinorbit.coupling.rebound.extra_forces import EXTRA_NG_BODY
    from spinorbit.coupling.rigid_body import CoupledRigidBody

    plain, with_body = _three_bodies("bs"), _three_bodies("bs")
    with_body.particles["Body"].m = 1e-18
    plain.particles["Body"].m = 1e-18
    CoupledRigidBody(with_body, "Body", make_body((4e-35, 5e-35, 6e-35), mass=1e-18), [1, 0, 0, 0, 0, 0, 1.0],
                     coupled=False)
    copies = [SimulationSnapshot.of(sim).build() for sim in (plain, with_body)]
    for copy in copies:
        copy.integrate(30.0)
    assert copies[0].particles["Body"].xyz == copies[1].particles["Body"].xyz
    assert copies[1]._afp.parameters[EXTRA_NG_BODY] == body_index(with_body, "Body")  # the A1-A3 term is on

    foreign = rebound.Simulation()
    foreign.add(m=1.0, name="Sun")
    foreign.additional_forces = lambda simulation: None
    with pytest.raises(ForceInstallError, match="did not install"):
        SimulationSnapshot.of(foreign)
