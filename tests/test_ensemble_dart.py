"""Members that run themselves (spinorbit.ensemble.ensemble.runs_itself) and the DART ensemble built on them
(spinorbit.ensemble.dart): rows, units, failures, checkpoints and executors; a DART member against the
direct computation with its inputs."""


import astropy.units as u
import numpy as np
import pytest
from astropy.utils.masked import Masked

from spinorbit.binary import propagate
from spinorbit.data import dart
from spinorbit.ensemble import Ensemble
from spinorbit.ensemble.dart import DART_OUTCOME_UNITS, DartMember, dart_member, dart_parameters
from spinorbit.ensemble.self_run import runs_itself


class Doubling:
    """A member that runs itself: its outcome is twice its parameter, or it fails for a negative one."""

    def __init__(self, x):
        self.x = x

    def outcome_row(self, at_days=None):
        if self.x < 0:
            raise ValueError(f"negative x = {self.x}")
        return {"twice": 2.0 * self.x, "sign": "positive", "even": int(self.x) % 2 == 0}


def doubling(x):
    return Doubling(x)


class Broken:
    def outcome_row(self, at_days=None):
        return [1.0]


def broken(x):
    return Broken()


def test_members_that_run_themselves_give_rows_units_failures_and_checkpoints(tmp_path):
    params = [{"x": float(x)} for x in (1, 2, -3, 4, 5)]
    ensemble = Ensemble(doubling, params, chunk_size=2, outcome_units={"twice": u.m})
    table = ensemble.run(executor="serial", checkpoint=tmp_path)
    assert runs_itself(doubling(1.0)) and table.meta["member_routes"] == {"self-run": 4}
    assert table["twice"].unit == u.m and isinstance(table["twice"], Masked)
    assert table["twice"].unmasked[[0, 1, 3, 4]].to_value(u.m).tolist() == [2.0, 4.0, 8.0, 10.0]
    assert table["twice"].mask.tolist() == [False, False, True, False, False]
    assert table["error"][2] == "ValueError: negative x = -3.0"
    assert list(table["sign"][[0, 1, 3, 4]]) == ["positive"] * 4 and table["even"][1]
    again = Ensemble(doubling, params, chunk_size=2, outcome_units={"twice": u.m})
    restored = again.run(executor="serial", checkpoint=tmp_path)
    assert again.last_run["members_run"] == 0 and again.last_run["members_restored"] == 5
    assert np.array_equal(restored["twice"].unmasked, table["twice"].unmasked)
    pooled = Ensemble(doubling, params, chunk_size=2, outcome_units={"twice": u.m}).run(executor=2)
    assert np.array_equal(pooled["twice"].unmasked, table["twice"].unmasked)


def test_a_member_whose_row_is_not_a_dict_is_a_recorded_failure():
    table = Ensemble(broken, [{"x": 1.0}]).run(executor="serial")
    assert "outcome_row expects to return a dict of plain numbers" in table["error"][0]
    with pytest.raises(Exception, match="outcome_units expects a dict"):
        Ensemble(doubling, [{"x": 1.0}], outcome_units={"twice": "m"})


def test_a_dart_member_is_the_direct_computation_with_its_inputs():
    # Three members of Naidu et al.'s Δv at order 2 over 10 orbits: member 0's row against the system built
    # and run directly from its row; the tilt keeps the along-track Δv at the sampled one (to rounding).
    params = dart_parameters(3, seed=37, orbits=10, order=2)
    table = Ensemble(dart_member, params, outcome_units=DART_OUTCOME_UNITS).run(executor="serial")
    assert table.meta["member_routes"] == {"self-run": 3}
    assert table["period_change"].unit == u.min and not any(table["error"])
    assert np.allclose(table["dv_along_track"].to_value(u.mm / u.s), params["dv"].to_value(u.mm / u.s),
                       rtol=1e-12, atol=0)
    row = params[0]
    extents = sorted((row["dimorphos_x"], row["dimorphos_y"], row["dimorphos_z"]), reverse=True)
    system = dart.dart_system(order=2, separation=row["separation"], density=row["density"],
                              didymos_radii=u.Quantity([row["didymos_equatorial"], row["didymos_polar"]]),
                              dimorphos_extents=u.Quantity(extents))
    state = dart.dart_state(system, row["separation"])
    member = dart_member(**{name: row[name] for name in params.colnames if not name.startswith("seed")})
    delta_v = -row["dv"] / np.cos(row["azimuth"]) / np.cos(row["elevation"]) * member.direction(state)
    times = np.linspace(0, 10, 401) * dart.PERIOD_BEFORE
    orbit = propagate(state.with_velocity_change(delta_v), times, rtol=1e-12).mutual_orbit()
    # the Δv and the output times are rebuilt here with other roundings, which 10 orbits carry to ~1e-12
    assert table["period_change"][0].to_value(u.min) == pytest.approx(
        (orbit.sidereal_period - dart.PERIOD_BEFORE).to_value(u.min), rel=1e-9)
    assert table["eccentricity"][0] == pytest.approx(orbit.eccentricity, rel=1e-9)


def test_a_beta_member_takes_dart_s_momentum():
    # β m U / M with DART's 579.4 kg at 6.1449 km/s on the member's Dimorphos, head-on (no tilt).
    member = DartMember(1206.0, (394.0, 290.0), (177.0, 174.0, 116.0), 2400.0, None, 3.61, 0.0, 0.0, 10, 2)
    row = member.outcome_row()
    expected = 3.61 * 579.4 * 6144.9 / row["dimorphos_mass"] * 1e3
    assert row["dv_total"] == pytest.approx(expected, rel=1e-14)
    assert row["dv_along_track"] == pytest.approx(-expected, rel=1e-14)


def test_bad_dart_parameters_are_refused_in_words():
    with pytest.raises(Exception, match="exactly one of dv"):
        dart_member(1.2 * u.km, 394 * u.m, 290 * u.m, 177 * u.m, 174 * u.m, 116 * u.m, 2.4 * u.g / u.cm ** 3)
    with pytest.raises(Exception, match="impulse 'dv' or 'beta'"):
        dart_parameters(2, impulse="momentum")
    with pytest.raises(Exception, match="no outcome at named"):
        DartMember(1206.0, (394.0, 290.0), (177.0, 174.0, 116.0), 2400.0, -2.63e-3, None, 0.0, 0.0, 10, 2).outcome_row(
            np.array([1.0]))
