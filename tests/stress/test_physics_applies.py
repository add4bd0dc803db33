"""Physics that no longer applies is refused, not reported (issue 36, class 3).

- a pair that is not bound has no mutual period and no libration lines (``spinorbit.core.binary.boundedness``);
- a period that the run is too short to resolve is refused, with the span it needs; one that it resolves
  comes with its resolution P²/T (``spinorbit.binary.run``).
"""

import math
import re

import astropy.units as u
import numpy as np
import pytest
from astropy import constants

from spinorbit import cli
from spinorbit.binary import BinaryState, BinarySystem, Figure, HeliocentricOrbit, propagate
from spinorbit.binary.run import MIN_LINE_CYCLES, MIN_LINE_SEPARATION
from spinorbit.core.binary.errors import UnboundPairError, UnresolvedPeriodError
from spinorbit.data.didymos import RELATIVE_SPEED, SEPARATION, didymos_state

G = constants.G.si.value
DENSITY = 2 * u.g / u.cm ** 3


def sphere_pair(separation_m, speed_m_s):
    """Two spheres (whose mutual potential is exactly G m_A m_B / r) on a planar orbit from +x along +y."""
    system = BinarySystem(Figure.sphere("A", 300 * u.m, DENSITY), Figure.sphere("B", 50 * u.m, DENSITY), order=2)
    return BinaryState.synchronous(system, separation_m * u.m, 1e-4 * u.rad / u.s, speed=speed_m_s * u.m / u.s)


def escape_speed(state, separation_m):
    total = (state.system.primary.mass + state.system.secondary.mass).to_value(u.kg)
    return math.sqrt(2 * G * total / separation_m)


def test_orbit_energy_of_two_spheres_is_the_point_mass_energy():
    # Spheres: U = G m_A m_B / r exactly, so E_orb = ½ ν v² − G m_A m_B / r is an independent check.
    state = sphere_pair(2000.0, 0.05)
    run = propagate(state, np.linspace(0, 1, 5) * u.h)
    m_a, m_b = state.system.primary.mass.to_value(u.kg), state.system.secondary.mass.to_value(u.kg)
    nu = m_a * m_b / (m_a + m_b)
    r = np.linalg.norm(run.states[:, :3], axis=1)
    v = np.linalg.norm(run.states[:, 3:6], axis=1)
    expected = 0.5 * nu * v ** 2 - G * m_a * m_b / r
    # 1e-12: the mutual field's sum of order-2 terms that cancel for spheres, rounded (~1e-16 each).
    np.testing.assert_allclose(run.orbit_energy().to_value(u.J), expected, rtol=1e-12)


@pytest.mark.parametrize("factor", [1.01, 3.0, 50.0])
def test_an_unbound_pair_has_no_mutual_period_or_libration(factor):
    separation = 2000.0
    state = sphere_pair(separation, 1.0)
    state = sphere_pair(separation, factor * escape_speed(state, separation))
    run = propagate(state, np.linspace(0, 20, 80) * u.h)
    assert not run.is_bound()
    for method in (run.mutual_period, run.libration_components):
        with pytest.raises(UnboundPairError, match=r"unbound at t = 0 h .*energy is .* ≥ 0 .*escape speed"):
            method()


def test_a_bound_pair_just_below_escape_speed_is_bound_but_two_hours_give_no_period():
    separation = 2000.0
    state = sphere_pair(separation, 1.0)
    state = sphere_pair(separation, 0.99 * escape_speed(state, separation))
    run = propagate(state, np.linspace(0, 2, 9) * u.h)
    assert run.is_bound() and run.unbound_reason() is None
    # Far above a day on so eccentric an orbit: two hours at pericentre turn the longitude by a fraction of a
    # revolution. The span asked for is that rate's revolution, a lower bound of the true period.
    with pytest.raises(UnresolvedPeriodError, match=r"covers 0\.\d+ of a revolution") as refusal:
        run.mutual_period()
    assert refusal.value.required_span > 10 * 2 * 3600


def test_a_circular_pair_over_a_few_revolutions_gives_kepler_s_period():
    separation = 2000.0
    state = sphere_pair(separation, 1.0)
    state = sphere_pair(separation, escape_speed(state, separation) / math.sqrt(2))
    kepler = 2 * math.pi * separation / (escape_speed(state, separation) / math.sqrt(2))
    run = propagate(state, np.linspace(0, 3 * kepler, 121) * u.s)
    # Two spheres on a circle: the longitude is linear in t; 1e-9 is DOP853's rtol 1e-12 over 3 orbits, amply.
    assert run.mutual_period().to_value(u.s) == pytest.approx(kepler, rel=1e-9)


def didymos_run(orbits, order=2):
    period = (2 * math.pi * SEPARATION / RELATIVE_SPEED).to(u.s)
    return propagate(didymos_state(order=order), np.linspace(0, orbits, orbits * 40 + 1) * period)


def test_a_didymos_run_of_four_orbits_does_not_resolve_the_libration_lines():
    # Free 13.8 h and forced 11.7 h: 1/Δf = 78 h, so 4 resolutions need ~310 h (26 orbits); 4 orbits give 48 h.
    run = didymos_run(4)
    with pytest.raises(UnresolvedPeriodError, match="not resolved by this run of 47.68 h") as refusal:
        run.libration_components()
    span = run.times[-1].to_value(u.s)
    assert refusal.value.required_span > 2 * span


def test_resolved_libration_lines_carry_their_resolution():
    run = didymos_run(30)
    parts = run.libration_components()
    span = run.times[-1]
    for period, resolution in ((parts.free_period, parts.free_resolution),
                               (parts.forced_period, parts.forced_resolution)):
        assert span / period >= MIN_LINE_CYCLES
        assert resolution.to_value(u.s) == pytest.approx((period ** 2 / span).to_value(u.s), rel=1e-14)
    assert abs(1 / parts.free_period - 1 / parts.forced_period) * span >= MIN_LINE_SEPARATION
    # Against the 100-orbit run's lines (13.8447 h, 11.7309 h at order 2): 30 orbits are 4.7 resolutions
    # apart, measured within 1e-4 of them, a small share of the ~4 % resolution.
    assert parts.free_period.to_value(u.h) == pytest.approx(13.8447, rel=2e-4)
    assert parts.forced_period.to_value(u.h) == pytest.approx(11.7309, rel=2e-4)
    assert parts.free_resolution.to_value(u.h) < 0.6 and parts.forced_resolution.to_value(u.h) < 0.4


def test_didymos_over_four_orbits_says_the_lines_are_not_resolved(capsys):
    # Four orbits give the mean orbit (3 revolutions at least) but not the ~51 h free libration (10 cycles).
    status = cli.main(["didymos", "--orbits", "4", "--order", "2"])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "mean sidereal period" in out and "free libration" not in out and "forced libration" not in out
    assert re.search(r"not resolved .*run of 47.69 h.*at least [\d.]+ h .*--orbits \d+ or more", out)
    status = cli.main(["didymos", "--orbits", "2", "--order", "2"])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "mean sidereal period" not in out
    assert re.search(r"not resolved .*mutual_orbit: the run of 23.84 h covers 2 revolutions.*--orbits 3 or more", out)


def test_beyond_the_hill_radius_the_pair_is_not_bound():
    # 2.3e11 kg at 1 au on a circle: r_H = a (m / 3 M_sun)^(1/3) ≈ 50 km. A circular mutual orbit of 200 km
    # has E_orb < 0, but the Sun holds the secondary; one of 20 km stays bound.
    sun = HeliocentricOrbit(1 * u.au)
    system = sphere_pair(1000.0, 0.1).system
    total = (system.primary.mass + system.secondary.mass).to_value(u.kg)
    hill = constants.au.si.value * (total / (3 * constants.M_sun.si.value)) ** (1 / 3)
    for separation, bound in ((20e3, True), (200e3, False)):
        state = sphere_pair(separation, 1.0)
        state = sphere_pair(separation, escape_speed(state, separation) / math.sqrt(2))
        run = propagate(state, np.linspace(0, 1, 5) * u.h, sun=sun)
        assert np.all(run.orbit_energy() < 0)
        assert run.is_bound() is bound
        if not bound:
            with pytest.raises(UnboundPairError, match="exceeds the Hill radius") as refusal:
                run.mutual_period()
            stated = float(re.search(r"Hill radius ([\d.e+]+) m", str(refusal.value)).group(1))
            assert stated == pytest.approx(hill, rel=1e-3)  # 4 digits printed


def test_didymos_after_an_unbinding_impact_says_unbound(capsys):
    # 2e6 kg at 6.1449 km/s, beta 3.61: dv = 9.88 m/s along the impulse, ~55x the circular speed of 0.177 m/s.
    status = cli.main(["didymos", "--impact", "--beta", "3.61", "--impactor-mass", "2e6", "--orbits", "30",
                       "--order", "2"])
    out, err = capsys.readouterr()
    assert status == 0, err
    nominal, impact = out.split("after impact")
    assert re.search(r"mutual orbit\s+mean sidereal period 11\.\d+ h", nominal)
    assert "mean sidereal period" not in impact and "libration " not in impact
    assert "period change  none: the pair is unbound after the impact" in impact
    assert re.search(r"unbound .*the pair is unbound at t = 0 h .*escape speed 0\.24\d+ m/s", impact)
