"""DART from the published system (spinorbit.data.dart): the fitted mass against the closed-form
MacCullagh orbit, the period measurement against Kepler, and the period change against the bars of
issue 37 (Naidu et al. 2024; Cheng et al. 2023 with Thomas et al. 2023)."""

import json
import math
import sys
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest

from spinorbit.binary import BinaryState, BinarySystem, Figure, propagate
from spinorbit.binary.system import G_SI
from spinorbit.core.binary.equations import OMEGA_B
from spinorbit.data import dart

sys.path.insert(0, str(Path(__file__).parent))

#: A copy of ../shared/data/didymos_dart_published.json (the project's reference data, outside the checkout).
DATA = Path(__file__).resolve().parent / "data" / "didymos_dart_published.json"
PERIOD_S = dart.PERIOD_BEFORE.to_value(u.s)
#: Ten orbits, 40 outputs per orbit: the mean period is the same to 0.002 min over 10, 20 or 40 orbits
#: (the model has no mass loss, so the post-impact orbit's mean motion does not drift; docs/binary.md).
TIMES = np.linspace(0.0, 10 * PERIOD_S, 401) * u.s


def period_change(state, delta_v):
    run = propagate(state.with_velocity_change(dart.along_track(state, delta_v)), TIMES, rtol=1e-12)
    return (run.mutual_orbit().sidereal_period - dart.PERIOD_BEFORE).to(u.min), run


@pytest.fixture(scope="module")
def nominal():
    return dart.dart_state()


def test_published_numbers_are_the_data_file_s():
    data = json.loads(DATA.read_text())
    before, impulse, measured = data["pre_impact"], data["impulse"], data["measured_outcome"]
    assert [dart.PERIOD_BEFORE.to_value(u.h), dart.PERIOD_BEFORE_SIGMA.to_value(u.h)] == before["mutual_orbit_period_h"]
    assert [dart.SEPARATION.to_value(u.km), dart.SEPARATION_SIGMA.to_value(u.km)] == before["semimajor_axis_km"]
    assert dart.DIDYMOS_SPIN_PERIOD.to_value(u.h) == before["didymos_spin_period_h"]
    assert "equatorial radius 394 +- 11 m and polar radius 290 +- 16 m" in before["didymos_shape"].replace(
        "m, polar", "m and polar")
    assert dart.DIDYMOS_RADII.to_value(u.m).tolist() == [394.0, 290.0]
    assert dart.DIDYMOS_RADII_SIGMA.to_value(u.m).tolist() == [11.0, 16.0]
    assert "extents 177 x 174 x 116 m (+- 2 x 4 x 2 m)" in before["dimorphos_shape"]
    assert dart.DIMORPHOS_EXTENTS.to_value(u.m).tolist() == [177.0, 174.0, 116.0]
    assert dart.DIMORPHOS_EXTENTS_SIGMA.to_value(u.m).tolist() == [2.0, 4.0, 2.0]
    assert [dart.DENSITY.to_value(u.g / u.cm ** 3), dart.DENSITY_SIGMA.to_value(u.g / u.cm ** 3)] == \
        before["bulk_density_g_cm3"]
    assert dart.DART_MASS.to_value(u.kg) == data["impact"]["spacecraft_mass_kg"]
    assert dart.DART_SPEED.to_value(u.km / u.s) == data["impact"]["relative_speed_km_s"]
    assert [dart.DV_CHENG.to_value(u.mm / u.s), dart.DV_CHENG_SIGMA.to_value(u.mm / u.s)] == \
        impulse["along_track_dv_mm_s_cheng2023"]
    assert [dart.DV_NAIDU.to_value(u.mm / u.s), dart.DV_NAIDU_SIGMA.to_value(u.mm / u.s)] == \
        impulse["along_track_dv_mm_s_naidu2024"]
    beta = impulse["beta_cheng2023"]
    assert (dart.BETA_CHENG, dart.BETA_CHENG_PLUS, dart.BETA_CHENG_MINUS) == (beta["value"], beta["plus"], beta["minus"])
    thomas, naidu = measured["period_change_min_thomas2023"], measured["period_change_initial_min_naidu2024"]
    assert dart.PERIOD_CHANGE_THOMAS.to_value(u.min) == thomas["value"]
    assert dart.PERIOD_CHANGE_THOMAS_3SIGMA.to_value(u.min) == thomas["uncertainty"] and thomas["sigma"] == 3
    assert dart.PERIOD_CHANGE_INITIAL_NAIDU.to_value(u.min) == naidu["value"]
    assert dart.PERIOD_CHANGE_INITIAL_NAIDU_SIGMA.to_value(u.s) == naidu["uncertainty_s"]
    total = measured["period_change_total_min_naidu2024"]
    assert dart.PERIOD_CHANGE_TOTAL_NAIDU.to_value(u.min) == total["value"]
    assert dart.PERIOD_CHANGE_TOTAL_NAIDU_SIGMA.to_value(u.s) == total["uncertainty_s"]


def test_order_two_mass_is_the_maccullagh_orbit_s():
    # At order 2 the mutual potential is point masses + both MacCullagh terms, so the circular orbit's
    # radial acceleration is G M / r² (1 + 3 [(a² − c²)_A + (2a² − b² − c²)_B] / (10 r²)) for Didymos's
    # spheroid with r in its equator and Dimorphos's long axis along r (closed forms, independent of the
    # inertia-integral expansion). The fitted G M therefore is Kepler's 4π² r³/P² divided by that factor.
    system = dart.dart_system(order=2)
    r = dart.SEPARATION.to_value(u.m)
    a, c = dart.DIDYMOS_RADII.to_value(u.m)
    ab, bb, cb = 0.5 * dart.DIMORPHOS_EXTENTS.to_value(u.m)
    factor = 1 + 3 * ((a ** 2 - c ** 2) + (2 * ab ** 2 - bb ** 2 - cb ** 2)) / (10 * r ** 2)
    gm = G_SI * (system.primary.mass + system.secondary.mass).to_value(u.kg)
    kepler = 4 * math.pi ** 2 * r ** 3 / PERIOD_S ** 2
    assert gm == pytest.approx(kepler / factor, rel=1e-12)  # rounding of a few sums (Brent's root to 1e-14)
    assert system.secondary.mass.to_value(u.kg) == pytest.approx(
        2400 * 4 / 3 * math.pi * ab * bb * cb, rel=1e-15)


def test_fitted_system_goes_round_in_the_measured_period(nominal):
    # The relative equilibrium integrated for 10 orbits: the measured mean period is the published one to
    # 1e-11 (DOP853 at rtol 1e-12 over 10 orbits; the least-squares slope's own rounding is ~1e-15), and
    # the orbit stays circular. The fitted mass is 1.6 % below Kepler's: the figures pull harder.
    run = propagate(nominal, TIMES, rtol=1e-12)
    orbit = run.mutual_orbit()
    assert orbit.sidereal_period.to_value(u.s) == pytest.approx(PERIOD_S, rel=1e-11)
    assert orbit.eccentricity < 1e-9 and orbit.apsidal_rate is None
    gm = G_SI * (nominal.system.primary.mass + nominal.system.secondary.mass).to_value(u.kg)
    kepler = 4 * math.pi ** 2 * dart.SEPARATION.to_value(u.m) ** 3 / PERIOD_S ** 2
    assert gm / kepler - 1 == pytest.approx(-0.0159, abs=0.0005)


def test_period_change_of_two_point_masses_is_kepler_s():
    # Two spheres: the orbit is Keplerian, and its period after the impulse follows from the energy alone
    # (vis-viva, a = 1 / (2/r − v²/GM)). The measured mean period must equal it: this checks the period
    # measurement on an eccentric orbit (e ≈ 0.03) against a closed form. Measured 1.1e-7 of the change
    # (2e-4 s): the fit leaves the orbit's third harmonic, ~e³ in the longitude. Tolerance 1e-6 of the
    # change, 1e-4 of the 16 s bar.
    radius = (394.0 ** 2 * 290.0) ** (1 / 3)
    system = BinarySystem(Figure.sphere("A", radius * u.m, 2900 * u.kg / u.m ** 3),
                          Figure.sphere("B", 75 * u.m, 2400 * u.kg / u.m ** 3), 4)
    state = BinaryState.synchronous(system, dart.SEPARATION, 0 * u.rad / u.s)
    r = dart.SEPARATION.to_value(u.m)
    gm = G_SI * (system.primary.mass + system.secondary.mass).to_value(u.kg)
    v = state.velocity.to_value(u.m / u.s)[1] + dart.DV_NAIDU.to_value(u.m / u.s)
    period_before = 2 * math.pi * math.sqrt(r ** 3 / gm)
    period_after = 2 * math.pi * math.sqrt((1 / (2 / r - v ** 2 / gm)) ** 3 / gm)
    times = np.linspace(0.0, 10 * period_before, 401) * u.s
    run = propagate(state.with_velocity_change(dart.along_track(state, dart.DV_NAIDU)), times, rtol=1e-12)
    measured = run.mutual_orbit().sidereal_period.to_value(u.s)
    assert measured - period_before == pytest.approx(period_after - period_before, rel=1e-6)


def test_period_change_at_order_two_agrees_with_heyoka():
    # tests/_heyoka_binary.py writes the order-2 problem from scratch (MacCullagh potential, symbolic
    # gradient, heyoka's Taylor method at 1e-15). The same post-impact state, both runs measured alike:
    # the mean periods agree to 4e-10 s (measured); 1e-6 s is 1e-7 of the 16 s bar.
    pytest.importorskip("heyoka")
    import _heyoka_binary as peer
    from spinorbit.binary.run import BinaryRun

    system = dart.dart_system(order=2)
    state = dart.dart_state(system)
    after = state.with_velocity_change(dart.along_track(state, dart.DV_NAIDU))
    t = TIMES.to_value(u.s)
    y0 = after.core_state()
    masses = (system.primary.mass.to_value(u.kg), system.secondary.mass.to_value(u.kg))
    rows = peer.propagate(y0, t[1:], masses, system.primary.moments.value, system.secondary.moments.value, G_SI)
    reference = BinaryRun(after, TIMES, np.vstack([y0, rows]), {}).mutual_orbit().sidereal_period
    ours = propagate(after, TIMES, rtol=1e-12).mutual_orbit().sidereal_period
    assert abs(ours - reference) < 1e-6 * u.s


def test_cheng_velocity_change_gives_thomas_period_change(nominal):
    # Bar of issue 37: Δv = −2.70 mm/s (Cheng et al. 2023) must give a period change within Thomas et
    # al. (2023)'s −33.0 ± 1.0 min (3σ). Measured −33.01 min.
    change, _ = period_change(nominal, dart.DV_CHENG)
    assert abs(change - dart.PERIOD_CHANGE_THOMAS) <= dart.PERIOD_CHANGE_THOMAS_3SIGMA


@pytest.mark.xfail(strict=True, reason=(
    "missed: Δv = −2.63 mm/s gives −32.19 min at the published central values, 31 s short of Naidu et al. "
    "(2024)'s −32.7 min ± 16 s. The change scales nearly as 1/separation (its size grows by 0.028 min per metre less): the bar is met "
    "for a pre-impact separation of 1.188 km, 0.5σ below the published 1.206 ± 0.035 km (docs/binary.md)"))
def test_naidu_velocity_change_gives_naidu_initial_period_change(nominal):
    # Bar of issue 37: Δv = −2.63 mm/s (Naidu et al. 2024) must give their immediate change −32.7 min
    # within their 1σ of 16 s.
    change, _ = period_change(nominal, dart.DV_NAIDU)
    assert abs(change - dart.PERIOD_CHANGE_INITIAL_NAIDU) <= dart.PERIOD_CHANGE_INITIAL_NAIDU_SIGMA


def test_bad_set_ups_are_refused_in_words():
    with pytest.raises(ValueError, match="equatorial ≥ polar"):
        dart.dart_system(didymos_radii=[290, 394] * u.m)
    with pytest.raises(ValueError, match="less than Dimorphos's"):
        dart.dart_system(separation=0.3 * u.km, period=100 * u.h)
    with pytest.raises(u.UnitsError):
        dart.dart_system(separation=1.2 * u.s)


def test_reshaped_dimorphos_keeps_mass_volume_and_angular_momentum(nominal):
    after = dart.reshaped(nominal)
    old, new = nominal.system.secondary, after.system.secondary
    a, b, c = new.semi_axes_m
    assert (a / b, a / c) == (pytest.approx(1.3, rel=1e-15), pytest.approx(1.6, rel=1e-15))
    assert np.prod(new.semi_axes_m) == pytest.approx(np.prod(old.semi_axes_m), rel=1e-14)
    assert new.mass == old.mass and after.system.primary is nominal.system.primary
    momentum_before = old.moments * nominal.secondary_spin
    assert np.allclose((new.moments * after.secondary_spin).value, momentum_before.value, rtol=1e-15, atol=0)
    with pytest.raises(ValueError, match="a/b ≥ 1 and a/c ≥ a/b"):
        dart.reshaped(nominal, (1.6, 1.3))


def test_an_elongated_dimorphos_tumbles_after_an_impulse_out_of_the_plane(nominal):
    # The reshaped Dimorphos (a/b 1.3, a/c 1.6) with 1° of the impulse out of the orbit plane: its wobble passes
    # 1° within 20 orbits (day 5.0 over the 100-orbit run of docs/binary.md); the pre-impact shape stays below
    # 0.25° with 10° (docs/binary.md's table). The wobble is checked against the SAM closed form of
    # docs/conventions.md, sin²θ_max = (M_y² + M_x² B(C − A)/(A(C − B)))/G², at the last output.
    times = np.linspace(0.0, 20, 801) * dart.PERIOD_BEFORE

    def kicked(state, degrees):
        dv = dart.along_track(state, dart.DV_NAIDU).to_value(u.m / u.s)
        return state.with_velocity_change((dv + [0, 0, abs(dv[1]) * math.tan(math.radians(degrees))]) * u.m / u.s)

    elongated = propagate(dart.reshaped(kicked(nominal, 1.0)), times, rtol=1e-12)
    oblate = propagate(kicked(nominal, 10.0), times, rtol=1e-12)
    assert elongated.secondary_wobble().max() > 1 * u.deg
    assert oblate.secondary_wobble().max() < 0.25 * u.deg
    big_a, big_b, big_c = oblate.initial.system.secondary.moments.value
    mx, my, mz = oblate.states[-1, OMEGA_B:OMEGA_B + 3] * [big_a, big_b, big_c]
    assert oblate.secondary_modes()[-1] == "SAM"
    sine = math.sqrt((my ** 2 + mx ** 2 * big_b * (big_c - big_a) / (big_a * (big_c - big_b))) / (mx ** 2 + my ** 2 + mz ** 2))
    assert oblate.secondary_wobble()[-1].to_value(u.rad) == pytest.approx(math.asin(sine), rel=1e-9)
