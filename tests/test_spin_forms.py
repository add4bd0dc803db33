"""Published spin forms both ways: DAMIT's pole form and the Pravec/Kaasalainen tumbler form.

Independent references: the attitude is rebuilt by hand from the active rotation matrices DAMIT and
Kaasalainen (2001) write, with astropy's ``BarycentricMeanEcliptic`` for the ecliptic; the tumbler's
periods and Euler angles are integrated with heyoka from Kaasalainen's Euler-angle equations (z-x-z,
angular momentum along the frame's z axis), which use neither spinorbit's elliptic functions nor its
periods. The round trips go through the published numbers and back.
"""

import math

import numpy as np
import pytest
from astropy import units as u
from astropy.coordinates import ICRS, BarycentricMeanEcliptic, SkyCoord
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.core.elements.canonical import MODE_LAM, MODE_SAM
from spinorbit.core.free_motion import from_periods
from spinorbit.quantities import QuantityInputError
from spinorbit.scene import Scene, SceneError
from spinorbit.spin_forms import SpinFormError

EPOCH = Time("2013-01-01T00:00:00", scale="tdb")
#: Round trips: each published number back to 1e-12, angles in radians and periods relative (the issue's bar).
ROUND_TRIP = 1e-12
#: Hand-built attitude against spinorbit's: astropy's ecliptic matrix (ERFA ecm06) and spinorbit's (R1(ε0)·B)
#: agree to 7e-16 (frames.py); products of five rotations add a few ulp more.
ATTITUDE_ATOL = 1e-13
#: heyoka at tol 1e-16 over one polhode period (up to ~60 rad of φ): its periods agree with spinorbit's elliptic
#: ones to ≤ 5e-15 relative and its Euler angles with the exact free flow's to ≤ 1.4e-14 rad (measured on the
#: three cases below); the bars leave a factor ~20 for other platforms' libm.
HEYOKA_PERIOD_RTOL = 1e-13
HEYOKA_ANGLE_ATOL = 3e-13
APOPHIS_MOMENTS = [0.61, 0.965, 1.0]  # Pravec et al. 2014: I1/I3, I2/I3 with I3 = 1
TOUTATIS_MOMENTS = [3.0836, 3.235, 1.0]  # Takahashi et al. 2013: z the long axis


def _active(axis, angle):
    """Active (counter-clockwise) rotation matrix, as DAMIT and Kaasalainen write R_x, R_y, R_z."""
    c, s = math.cos(angle), math.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _icrf_to_ecliptic_astropy():
    """v_ecl = E v_icrf from astropy's transformation of the ICRS axes."""
    axes = SkyCoord(x=[1, 0, 0], y=[0, 1, 0], z=[0, 0, 1], frame=ICRS(), representation_type="cartesian")
    ecl = axes.transform_to(BarycentricMeanEcliptic(equinox="J2000")).cartesian
    return np.array([ecl.x.value, ecl.y.value, ecl.z.value])


def _wrap(angle):
    return (angle + math.pi) % (2 * math.pi) - math.pi


def test_from_pole_is_damits_rotation_matrix_built_by_hand():
    body = RigidBody([2.0, 2.5, 3.0])
    lam, beta, phase, period = 123.4, -37.5, 211.0, 7.81 * u.hour
    state = RotationState.from_pole(body, lam * u.deg, beta * u.deg, period, EPOCH, phase=phase * u.deg)
    ast_to_ecl = _active("z", math.radians(lam)) @ _active("y", math.radians(90 - beta)) @ _active("z", math.radians(phase))
    expected = ast_to_ecl.T @ _icrf_to_ecliptic_astropy()  # v_body = R v_icrf
    assert np.abs(state.attitude_matrix - expected).max() < ATTITUDE_ATOL
    assert state.mode == "permanent rotation" and state.epoch is EPOCH
    omega = state.angular_velocity.to_value(u.rad / u.hour)
    assert np.allclose(omega, [0, 0, 2 * math.pi / 7.81], rtol=1e-15, atol=0)  # about z, the largest moment
    lon, lat = state.pole_ecliptic
    assert lon.to_value(u.deg) == pytest.approx(lam, abs=1e-11) and lat.to_value(u.deg) == pytest.approx(beta, abs=1e-11)


def test_from_pole_turns_the_largest_moment_onto_damits_z():
    body = RigidBody([3.0, 1.0, 2.0])  # largest moment on x: DAMIT's (x, y, z) are the user's (y, z, x)
    state = RotationState.from_pole(body, 10 * u.deg, 60 * u.deg, 5 * u.hour, EPOCH)
    assert state.angular_velocity.to_value(u.rad / u.hour)[0] == pytest.approx(2 * math.pi / 5, rel=1e-15)
    assert state.pole().axes == "yzx"
    with pytest.raises(SpinFormError, match="largest moment"):
        RotationState.from_pole(body, 10 * u.deg, 60 * u.deg, 5 * u.hour, EPOCH, axes="xyz")


@pytest.mark.parametrize("frame", ["ecliptic", "icrf"])
def test_pole_round_trip(frame):
    rng = np.random.default_rng(35)
    body = RigidBody([1.0, 1.3, 1.7])
    worst = np.zeros(4)
    for _ in range(200):
        lam, phase = rng.uniform(0, 360, 2)
        beta = math.degrees(math.asin(rng.uniform(-0.999, 0.999)))
        period = rng.uniform(2, 2000) * u.hour
        state = RotationState.from_pole(body, lam * u.deg, beta * u.deg, period, EPOCH, phase=phase * u.deg, frame=frame)
        back = state.pole(frame=frame)
        again = RotationState.from_pole(body, **back.arguments())
        worst = np.maximum(worst, [abs(_wrap(back.pole_lon.to_value(u.rad) - math.radians(lam))),
                                   abs(back.pole_lat.to_value(u.rad) - math.radians(beta)),
                                   abs((back.period / period).to_value(u.one) - 1),
                                   abs(_wrap(back.phase.to_value(u.rad) - math.radians(phase)))])
        assert np.abs(again.attitude_matrix - state.attitude_matrix).max() < ROUND_TRIP
        assert back.wobble.to_value(u.rad) < ROUND_TRIP and back.epoch is EPOCH
    assert worst.max() < ROUND_TRIP, worst


def test_pole_of_a_tumbler_is_refused_and_its_wobble_said():
    state = RotationState.from_tumbling(RigidBody(APOPHIS_MOMENTS), 263 * u.hour, 27.38 * u.hour, 250 * u.deg,
                                        -75 * u.deg, 0 * u.deg, None, 0 * u.deg, EPOCH)
    with pytest.raises(SpinFormError, match=r"tumbles.*tumbling_parameters"):
        state.pole()
    loose = state.pole(max_wobble=90 * u.deg)  # a coarse description, asked for: P is the sidereal period
    assert loose.period.to_value(u.hour) == pytest.approx(state.sidereal_period.to_value(u.hour), rel=1e-15)
    assert 40 < loose.wobble.to_value(u.deg) < 60


def _tumbling_by_hand(body_moments, p, frame_matrix):
    """Attitude and body momentum direction of Kaasalainen's form, from the active rotation matrices."""
    angles = [math.radians(p[k]) for k in ("lon", "lat", "phi", "theta", "psi")]
    lon, lat, phi, theta, psi = angles
    ast_to_ecl = (_active("z", lon) @ _active("y", math.pi / 2 - lat) @ _active("z", phi) @ _active("x", theta)
                  @ _active("z", psi))
    direction = np.array([math.sin(theta) * math.sin(psi), math.sin(theta) * math.cos(psi), math.cos(theta)])
    return ast_to_ecl.T @ frame_matrix, direction


@pytest.mark.parametrize("moments, mode, p_psi, p_phi", [
    (APOPHIS_MOMENTS, "SAM", 263 * u.hour, 27.38 * u.hour),
    (TOUTATIS_MOMENTS, "LAM", 5.37 * u.day, 7.41 * u.day),
])
def test_from_tumbling_is_kaasalainens_rotation_matrix_built_by_hand(moments, mode, p_psi, p_phi):
    body = RigidBody(moments)
    state = RotationState.from_tumbling(body, p_psi, p_phi, 250 * u.deg, -75 * u.deg, 33 * u.deg, None, 47 * u.deg,
                                        EPOCH, mode=mode)
    theta = state.tumbling_parameters().theta0.to_value(u.deg)  # the θ0 that P_ψ, P_φ and ψ0 imply
    attitude, direction = _tumbling_by_hand(moments, dict(lon=250, lat=-75, phi=33, theta=theta, psi=47),
                                            _icrf_to_ecliptic_astropy())
    assert np.abs(state.attitude_matrix - attitude).max() < ATTITUDE_ATOL
    momentum = state.angular_momentum.value
    assert np.abs(momentum / np.linalg.norm(momentum) - direction).max() < 1e-15 * 10
    assert state.mode == mode and state.epoch is EPOCH


def _heyoka_euler_angles(moments, big_l, angles, span):
    """Kaasalainen's (Landau–Lifshitz) z-x-z Euler-angle equations of free rotation, integrated by heyoka.

    φ̇ = L (sin²ψ/I1 + cos²ψ/I2), θ̇ = L (1/I1 − 1/I2) sin θ sin ψ cos ψ, ψ̇ = L cos θ (1/I3 − sin²ψ/I1 − cos²ψ/I2).
    Returns (the time ψ has turned by one full turn, φ turned in that time, heyoka's integrator).
    """
    hy = pytest.importorskip("heyoka")
    phi, theta, psi = hy.make_vars("phi", "theta", "psi")
    i1, i2, i3 = moments
    s, c = hy.sin(psi), hy.cos(psi)
    rates = [(phi, big_l * (s * s / i1 + c * c / i2)), (theta, big_l * (1 / i1 - 1 / i2) * hy.sin(theta) * s * c),
             (psi, big_l * hy.cos(theta) * (1 / i3 - s * s / i1 - c * c / i2))]
    turn = math.copysign(2 * math.pi, math.cos(angles[1]) * (1 / i3 - 1 / i2))  # the sense ψ turns in
    ta = hy.taylor_adaptive(rates, list(angles), tol=1e-16, t_events=[hy.t_event(psi - (angles[2] + turn))])
    ta.propagate_until(span)
    return ta.time, ta.state[0] - angles[0], ta


@pytest.mark.parametrize("moments, mode, p_psi, p_phi, theta0", [
    (APOPHIS_MOMENTS, "SAM", 263 * u.hour, 27.38 * u.hour, None),
    (APOPHIS_MOMENTS, "SAM", 263 * u.hour, 27.38 * u.hour, 150 * u.deg),  # the other sense (−C)
    (TOUTATIS_MOMENTS, "LAM", 5.37 * u.day, 7.41 * u.day, None),
])
def test_periods_and_angles_against_heyoka(moments, mode, p_psi, p_phi, theta0):
    body = RigidBody(moments)
    kwargs = dict(mode=mode, theta_tolerance=180 * u.deg)  # theta0 only picks the branch here
    state = RotationState.from_tumbling(body, p_psi, p_phi, 100 * u.deg, 20 * u.deg, 33 * u.deg, theta0, 47 * u.deg,
                                        EPOCH, **kwargs)
    published = state.tumbling_parameters()
    angles = [published.phi0.to_value(u.rad), published.theta0.to_value(u.rad), published.psi0.to_value(u.rad)]
    big_l = float(np.linalg.norm(state.angular_momentum.value))  # moment unit × rad/day
    days = p_psi.to_value(u.day)
    psi_period, phi_turned, ta = _heyoka_euler_angles(moments, big_l, angles, 2 * days)
    assert psi_period / days == pytest.approx(1, rel=HEYOKA_PERIOD_RTOL)
    assert 2 * math.pi * psi_period / abs(phi_turned) / p_phi.to_value(u.day) == pytest.approx(1, rel=HEYOKA_PERIOD_RTOL)
    # the exact free flow, decomposed into the published form, follows heyoka's Euler angles
    ta.propagate_until(0.37 * days)
    quaternions, omegas = state.propagate_torque_free(0.37 * days * u.day)
    later = RotationState(body, quaternions[0], omegas[0]).tumbling_parameters()
    got = [later.phi0.to_value(u.rad), later.theta0.to_value(u.rad), later.psi0.to_value(u.rad)]
    assert max(abs(_wrap(g - h)) for g, h in zip(got, ta.state)) < HEYOKA_ANGLE_ATOL


def _random_tumbler(rng, moments, mode):
    """A body and the published form of a random motion of it, its shape μ drawn in (0.001, 0.999)."""
    body = RigidBody(moments)
    code = MODE_SAM if mode == "SAM" else MODE_LAM
    unit_psi, unit_phi = from_periods.unit_periods(rng.uniform(0.001, 0.999), code, *body.principal_moments)
    p_psi = rng.uniform(5, 500) * u.hour
    theta_branch = None if rng.uniform() < 0.5 else 170 * u.deg
    return body, dict(p_psi=p_psi, p_phi=p_psi * unit_phi / unit_psi, momentum_lon=rng.uniform(0, 360) * u.deg,
                      momentum_lat=math.degrees(math.asin(rng.uniform(-0.99, 0.99))) * u.deg,
                      phi0=rng.uniform(0, 360) * u.deg, theta0=theta_branch, psi0=rng.uniform(0, 360) * u.deg,
                      epoch=EPOCH, mode=mode, theta_tolerance=180 * u.deg)


@pytest.mark.parametrize("moments, mode", [(APOPHIS_MOMENTS, "SAM"), ([1.0, 1.2, 1.5], "SAM"), (TOUTATIS_MOMENTS, "LAM"),
                                           ([1.5, 1.2, 1.0], "LAM")])
def test_tumbling_round_trip(moments, mode):
    rng = np.random.default_rng(2005)
    worst = np.zeros(7)
    for _ in range(60):
        body, given = _random_tumbler(rng, moments, mode)
        state = RotationState.from_tumbling(body, **given)
        back = state.tumbling_parameters()
        again = RotationState.from_tumbling(body, **back.arguments())
        worst = np.maximum(worst, [
            abs((back.p_psi / given["p_psi"]).to_value(u.one) - 1), abs((back.p_phi / given["p_phi"]).to_value(u.one) - 1),
            abs(_wrap((back.momentum_lon - given["momentum_lon"]).to_value(u.rad))),
            abs((back.momentum_lat - given["momentum_lat"]).to_value(u.rad)),
            abs(_wrap((back.phi0 - given["phi0"]).to_value(u.rad))), abs(_wrap((back.psi0 - given["psi0"]).to_value(u.rad))),
            np.abs(again.attitude_matrix - state.attitude_matrix).max()])
        assert back.mode == mode and back.axes == "xyz"
        assert (back.i1_i3, back.i2_i3) == pytest.approx((moments[0] / moments[2], moments[1] / moments[2]), rel=1e-15)
        omega, omega_again = state.angular_velocity_rad_per_day, again.angular_velocity_rad_per_day
        assert np.linalg.norm(omega_again - omega) / np.linalg.norm(omega) < ROUND_TRIP
    assert worst.max() < ROUND_TRIP, worst


def test_period_ratio_grows_with_the_shape_in_both_modes():
    # the bisection of motion_of_periods relies on it: P_ψ/P_φ increasing in μ, to rounding
    for code, moments in ((MODE_SAM, (0.61, 0.965, 1.0)), (MODE_LAM, (1.0, 3.0836, 3.235)), (MODE_SAM, (1, 1.0001, 3))):
        mus = 1 / (1 + np.exp(-np.linspace(-30, 30, 600)))
        ratios = np.array([np.divide(*from_periods.unit_periods(m, code, *moments)) for m in mus])
        assert np.all(np.diff(ratios) > -4 * np.finfo(float).eps * ratios[1:])
        assert ratios[-1] > 2 * ratios[0]


def test_published_tumbler_inputs_are_checked():
    body = RigidBody(APOPHIS_MOMENTS)
    args = (263 * u.hour, 27.38 * u.hour, 250 * u.deg, -75 * u.deg, 0 * u.deg, None, 0 * u.deg, EPOCH)
    with pytest.raises(SpinFormError, match=r"outside the range \(7.56"):
        RotationState.from_tumbling(body, 263 * u.hour, 40 * u.hour, *args[2:])  # P_ψ/P_φ below any SAM's
    with pytest.raises(SpinFormError, match="within rounding of the separatrix"):
        RotationState.from_tumbling(body, 263 * u.hour, 263 / 87.2 * u.hour, *args[2:])
    with pytest.raises(SpinFormError, match="fix it to 53.83"):
        RotationState.from_tumbling(body, *args[:5], 20 * u.deg, *args[6:])  # θ0 not the motion's
    with pytest.raises(SpinFormError, match="largest moment"):
        RotationState.from_tumbling(body, *args, axes="yzx", mode="SAM")
    with pytest.raises(SpinFormError, match="triaxial"):
        RotationState.from_tumbling(RigidBody([1, 1, 2]), *args)
    with pytest.raises(SpinFormError, match="intermediate"):
        RotationState.from_tumbling(RigidBody([1, 3, 2]), *args)
    with pytest.raises(SpinFormError, match="scalar astropy Time"):
        RotationState.from_tumbling(body, *args[:7], "2013-01-01")
    with pytest.raises(SpinFormError, match="permanent rotation"):
        RotationState.from_pole(body, 0 * u.deg, 0 * u.deg, 5 * u.hour, EPOCH).tumbling_parameters()


@pytest.mark.parametrize("position, hint", [(0, "8 \\* u.hour"), (2, "250 \\* u.deg"), (4, "10 \\* u.deg")])
def test_bare_floats_are_refused_in_the_published_forms(position, hint):
    args = [263 * u.hour, 27.38 * u.hour, 250 * u.deg, -75 * u.deg, 10 * u.deg, None, 20 * u.deg, EPOCH]
    args[position] = 263.0 if position == 0 else 0.2
    with pytest.raises(QuantityInputError, match=hint):
        RotationState.from_tumbling(RigidBody(APOPHIS_MOMENTS), *args)
    with pytest.raises(QuantityInputError, match="8 \\* u.hour"):
        RotationState.from_pole(RigidBody(APOPHIS_MOMENTS), 1 * u.deg, 2 * u.deg, 8.0, EPOCH)


def test_epoch_travels_with_the_state_into_the_scene():
    state = RotationState.from_pole(RigidBody([1.0, 1.2, 1.5]), 80 * u.deg, 30 * u.deg, 8 * u.hour, EPOCH)
    times = EPOCH + [0.5, 1.0] * u.day
    implicit = Scene(state, times=times).run().table
    explicit = Scene(state, EPOCH, times).run().table
    same_instant = Scene(state, Time(EPOCH.utc), times).run().table  # another scale, the same instant
    for table in (explicit, same_instant):
        assert np.array_equal(np.asarray(table["q_w"]), np.asarray(implicit["q_w"]))
    with pytest.raises(SceneError, match="not the state's own epoch"):
        Scene(state, EPOCH + 1 * u.s, times)
    with pytest.raises(SceneError, match="carries none"):
        Scene(state.with_epoch(None), times=times)
    with pytest.raises(AttributeError):
        state.epoch = EPOCH + 1 * u.day  # states are immutable
    moved = state.with_epoch(EPOCH + 1 * u.day)
    assert moved.epoch == EPOCH + 1 * u.day and state.epoch is EPOCH
    assert np.array_equal(moved.quaternion, state.quaternion)
    assert RotationState(state.body, [1, 0, 0, 0], [0, 0, 1] * u.rad / u.day).epoch is None


def test_apophis_data_module_is_the_published_tumbler():
    """Pravec et al. (2014): P_ψ = 263 ± 6 h, P_φ = 27.38 ± 0.07 h, L to ecliptic (250°, −75°), I1/I3 = 0.61,
    I2/I3 = 0.965, SAM, E/E0 = 1.024 ± 0.013 (3σ). The state is built from the first five; its periods must
    give them back (to the round-trip bar) and its E/E0, an outcome, must lie in the published interval."""
    from spinorbit.data.asteroids import APOPHIS_PHI0, APOPHIS_PSI0, APOPHIS_STATE_EPOCH, apophis_rotation_state

    state = apophis_rotation_state()
    p_psi, p_phi = state.periods
    assert (p_psi / (263 * u.hour)).to_value(u.one) == pytest.approx(1, rel=ROUND_TRIP)
    assert (p_phi / (27.38 * u.hour)).to_value(u.one) == pytest.approx(1, rel=ROUND_TRIP)
    assert state.mode == "SAM" and state.sense == "+C" and state.epoch is APOPHIS_STATE_EPOCH
    assert abs(state.energy_ratio - 1.024) <= 0.013
    published = state.tumbling_parameters()
    assert published.momentum_lon.to_value(u.deg) == pytest.approx(250, abs=1e-11)
    assert published.momentum_lat.to_value(u.deg) == pytest.approx(-75, abs=1e-11)
    assert (published.i1_i3, published.i2_i3) == (0.61, 0.965)
    assert abs(_wrap((published.phi0 - APOPHIS_PHI0).to_value(u.rad))) < ROUND_TRIP
    assert abs(_wrap((published.psi0 - APOPHIS_PSI0).to_value(u.rad))) < ROUND_TRIP
    # another phase of the same motion at the same epoch; other moment ratios keep the published periods
    later = apophis_rotation_state(0.25)
    assert later.epoch is APOPHIS_STATE_EPOCH and later.periods[0].to_value(u.hour) == pytest.approx(263, rel=1e-12)
    other = apophis_rotation_state(moment_ratios=(0.64, 0.97))  # Lee et al. 2022's ratios
    assert [p.to_value(u.hour) for p in other.periods] == pytest.approx([263, 27.38], rel=1e-12)
