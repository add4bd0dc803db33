"""The vectorised table columns against one RotationState per row (the definition they replace).

Tolerances are units of roundoff with their reason next to them: the columns divide by norms formed in
another order than RotationState's (np.linalg.norm of one vector uses a dot product, of rows a sum),
which may move the last bit; everything else is the same arithmetic.
"""

import math

import numpy as np
import pytest
from astropy import units as u

from spinorbit import RigidBody, RotationState
from spinorbit.core.math.rotations import quat_to_attitude
from spinorbit.state import InvalidStateError
from spinorbit.state_table import from_principal, omega_array, quaternion_array, table_columns

COLUMNS = ["q_w", "q_x", "q_y", "q_z", "omega_x", "omega_y", "omega_z", "pole_ra", "pole_dec", "pole_lon", "pole_lat",
           "mode", "energy_ratio", "P_psi", "P_phi", "sidereal_period", "wobble_amplitude"]
#: A pole angle from directions that differ by ≤ 4 ulps (see momentum directions below), in degrees:
#: atan2/asin of unit components move by ≤ 4 ulps / cos, a few 1e-14 deg at the latitudes used here.
POLE_ATOL_DEG = 1e-12

EPS = np.finfo(float).eps
#: θ_max of the propagated momentum against the initial one's, in ulps (× 1/cos θ_max near the separatrix).
WOBBLE_ULPS = 8


def _states():
    """(name, state): triaxial SAM and LAM, both axisymmetric kinds, near and on the separatrix, permanent rotation."""
    near = RigidBody([1.0, 2.0, 2.5])  # separatrix where b−c M_z² = (a−b) M_x², i.e. M_z = √5 M_x
    return [
        ("triaxial SAM", RotationState.from_euler313(RigidBody([0.61, 0.965, 1.0]), 10 * u.deg, 40 * u.deg,
                                                     70 * u.deg, [5, 3, 40] * u.deg / u.hour)),
        ("triaxial LAM", RotationState.from_euler313(RigidBody([3.0836, 3.235, 1.0]), 145.498 * u.deg, 65.865 * u.deg,
                                                     241.524 * u.deg, [14.51, 33.529, -98.709] * u.deg / u.day)),
        ("oblate A = B", RotationState.from_euler313(RigidBody([1.0, 1.0, 2.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                                     [5, 3, 40] * u.deg / u.hour)),
        ("prolate B = C", RotationState.from_angular_momentum(RigidBody([2.0, 1.0, 2.0]), [0.6, 0.0, 0.8, 0.0],
                                                              [0.3, 1.0, -0.2] * u.rad / u.day)),
        ("near separatrix", RotationState.from_angular_momentum(near, [1.0, 0.0, 0.0, 0.0],
                                                                [1.0, 0.3, math.sqrt(5.0) * (1 + 1e-7)] * u.rad / u.day)),
        # (3, 4, 6) has a − b = b − c = 1/12 exactly: M_x = M_z is on the separatrix without rounding.
        ("separatrix", RotationState.from_angular_momentum(RigidBody([3.0, 4.0, 6.0]), [1.0, 0.0, 0.0, 0.0],
                                                           [1.0, 0.5, 1.0] * u.rad / u.day)),
        ("permanent rotation", RotationState(near, [0.8, 0.6, 0.0, 0.0], [0.0, 1.7, 0.0] * u.rad / u.day)),
    ]


STATES = _states()
TIMES = np.linspace(0.0, 60.0, 97)


def _rows(state):
    quaternions, omegas = state.propagate_torque_free(TIMES * u.day)
    omegas = omegas.to_value(u.rad / u.day)
    return quaternions, omegas, [RotationState(state.body, q, w * u.rad / u.day) for q, w in zip(quaternions, omegas)]


@pytest.mark.parametrize("name, state", STATES, ids=[n for n, _ in STATES])
def test_columns_are_each_rows_rotation_state(name, state):
    quaternions, omegas, rows = _rows(state)
    columns = table_columns(state.body, quaternions, omegas, motion="rows")
    assert list(columns) == COLUMNS
    # The norms differ from RotationState's by the order of the sum: ≤ 1 ulp of each unit component.
    assert np.abs(quaternion_array(columns) - [s.quaternion for s in rows]).max() <= EPS
    assert np.array_equal(omega_array(columns), [s.angular_velocity.value for s in rows])
    # Rᵀ I ω of unit-size rows, then a norm: a few ulps of 1; the angles of those directions:
    for key, index, which in (("pole_ra", 0, "pole_icrf"), ("pole_dec", 1, "pole_icrf"), ("pole_lon", 0, "pole_ecliptic"),
                              ("pole_lat", 1, "pole_ecliptic")):
        expected = np.array([getattr(s, which)[index].to_value(u.deg) for s in rows])
        difference = (columns[key].to_value(u.deg) - expected + 180.0) % 360.0 - 180.0  # RA, λ wrap at 360
        assert np.abs(difference).max() <= POLE_ATOL_DEG
    # Mode, E/E0 and the periods come from the very kernels RotationState calls: bit for bit (hours:
    # the same day values times one conversion factor).
    assert list(columns["mode"]) == [s.mode for s in rows]
    assert np.array_equal(columns["energy_ratio"], [s.energy_ratio for s in rows])
    assert np.array_equal(columns["P_psi"].to_value(u.h), [s.periods[0].to_value(u.h) for s in rows])
    assert np.array_equal(columns["P_phi"].to_value(u.h), [s.periods[1].to_value(u.h) for s in rows])
    assert np.array_equal(columns["sidereal_period"].to_value(u.h), [s.sidereal_period.to_value(u.h) for s in rows])
    assert columns["P_psi"].unit == columns["P_phi"].unit == columns["sidereal_period"].unit == u.h
    assert np.array_equal(columns["wobble_amplitude"].to_value(u.deg), [s.wobble_amplitude.to_value(u.deg) for s in rows])


@pytest.mark.parametrize("name, state", STATES, ids=[n for n, _ in STATES])
def test_torque_free_constants_are_the_rows_values_to_rounding(name, state):
    """Mode, E/E0 and the periods are constants of the torque-free motion: the initial state's values,
    taken once, are every propagated row's to the rounding of the propagated momentum (on the exact
    separatrix too: the flow's rows stay on it here, mode "separatrix" and infinite periods)."""
    quaternions, omegas, rows = _rows(state)
    constant = table_columns(state.body, quaternions, omegas, motion=state)
    each = table_columns(state.body, quaternions, omegas, motion="rows")
    assert np.array_equal(quaternion_array(constant), quaternion_array(each))
    for key in ("pole_ra", "pole_dec", "pole_lon", "pole_lat"):
        assert np.array_equal(constant[key], each[key])
    assert list(constant["mode"]) == list(each["mode"]) == [state.mode] * len(TIMES)
    # E/E0 of a rounded momentum: a few ulps (measured ≤ 1.5 ulps).
    assert np.abs(constant["energy_ratio"] / each["energy_ratio"] - 1).max() <= 4 * EPS
    # The periods are smooth in (G, T) except through 1 − m, whose rounding from b − d is amplified by
    # b/|b − d| (~1e7 near the separatrix here; K ~ ln(1/(1 − m)) damps it): measured 6.1e-11 relative
    # there, so 1e-9; ≤ 2.5 ulps elsewhere, so 8 ulps.
    tolerance = 1e-9 if name == "near separatrix" else 8 * EPS
    # θ_max of a rounded momentum: a few ulps, amplified near the separatrix by 1/cos θ_max (the rounding ε of M
    # moves cos² θ_max by ~ε; measured 3.6e-13 rad at cos θ_max = 4e-4, i.e. ~0.7 ulp × 1/cos θ_max).
    wobble = np.abs(constant["wobble_amplitude"] - each["wobble_amplitude"]).to_value(u.rad)
    amplification = 1.0 / max(math.cos(constant["wobble_amplitude"][0].to_value(u.rad)), 1e-3)
    assert wobble.max() <= WOBBLE_ULPS * EPS * amplification, wobble.max()
    for key in ("P_psi", "P_phi", "sidereal_period"):
        a, b = constant[key].to_value(u.day), each[key].to_value(u.day)
        finite = np.isfinite(a)
        assert np.array_equal(finite, np.isfinite(b)) and (finite.all() or state.mode != "SAM")
        assert np.abs(a[finite] / b[finite] - 1).max(initial=0.0) <= tolerance


def test_from_principal_is_rotation_state_from_matrix():
    """Core rows (principal q, ω) → user axes as RotationState.from_matrix(body, Pᵀ R(q), Pᵀ ω) makes them."""
    body = RigidBody([3.0836, 3.235, 1.0])  # principal axes a permutation of the user's
    rng = np.random.default_rng(5)
    q = rng.normal(size=(50, 4))
    rows = np.hstack([q / np.linalg.norm(q, axis=1, keepdims=True), rng.normal(size=(50, 3))])
    quaternions, omegas = from_principal(body, rows)
    p = body.to_principal
    reference = [RotationState.from_matrix(body, p.T @ quat_to_attitude(np.ascontiguousarray(y[:4])), (p.T @ y[4:]) * u.rad / u.day)
                 for y in rows]
    # Same representative (largest component positive); ≤ 1 ulp from the second normalisation.
    assert np.abs(quaternions - [s.quaternion for s in reference]).max() <= 2 * EPS
    assert np.array_equal(omegas, [s.angular_velocity.value for s in reference])


def test_rows_that_are_not_states_are_refused():
    body = RigidBody([1.0, 2.0, 2.5])
    with pytest.raises(InvalidStateError, match="unit norm"):
        table_columns(body, [[1.0, 0.1, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    with pytest.raises(InvalidStateError, match="finite"):
        table_columns(body, [[math.nan, 0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    with pytest.raises(InvalidStateError, match="not rotating"), np.errstate(invalid="ignore"):
        table_columns(body, [[1.0, 0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]], motion="rows")
    with pytest.raises(ValueError, match="motion expects"):
        table_columns(body, [[1.0, 0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]], motion="each")


def test_one_way_table_rows_are_their_rotation_states_and_osculate():
    """Under a torque the mode, E/E0 and periods of each row are that row's own (osculating) values."""
    from astropy.time import Time

    from spinorbit.core.model.perturbers import fixed_source
    from spinorbit.coupling.one_way import propagate_one_way
    from spinorbit.scene.sampling import NoSamples
    from spinorbit.time import tdb_days

    state = STATES[0][1]
    epoch = Time("2020-01-01", scale="tdb")
    times = epoch + np.linspace(0.1, 2.0, 40) * u.day
    start = float(sum(tdb_days(epoch)))
    # A strong nearby mass (GM 1e-3 au³/day² at 0.01 au) changes the periods visibly within 2 d.
    table = propagate_one_way(state, epoch, times, NoSamples(start, start + 2.0),
                              extra_sources=[fixed_source(1e-3, [0.01, 0.004, 0.002])])
    rows = [RotationState(state.body, q, w * u.rad / u.day) for q, w in zip(quaternion_array(table), omega_array(table))]
    assert np.array_equal(quaternion_array(table[3]), quaternion_array(table)[3:4])  # a Row gives its (1, 4)
    assert np.array_equal(omega_array(table[3]), omega_array(table)[3:4])
    assert np.abs(quaternion_array(table) - [s.quaternion for s in rows]).max() <= EPS  # re-normalisation: ≤ 1 ulp
    assert np.abs(table["pole_dec"].to_value(u.deg) - [s.pole_icrf[1].to_value(u.deg) for s in rows]).max() <= POLE_ATOL_DEG
    # the first row is the first time asked (through TDB day floats: ~1e-11 d, so 10 µs)
    assert abs((table["time"][0] - times[0]).to_value(u.s)) < 1e-5 and table.meta["epoch"] == epoch.tdb.isot and table.meta["frame"] == "ICRF"
    assert list(table["mode"]) == [s.mode for s in rows]
    assert np.array_equal(table["energy_ratio"], [s.energy_ratio for s in rows])
    assert np.array_equal(table["P_psi"].to_value(u.h), [s.periods[0].to_value(u.h) for s in rows])
    assert np.array_equal(table["P_phi"].to_value(u.h), [s.periods[1].to_value(u.h) for s in rows])
    assert np.array_equal(table["sidereal_period"].to_value(u.h), [s.sidereal_period.to_value(u.h) for s in rows])
    assert np.ptp(table["P_psi"].to_value(u.day)) > 1e-6 * table["P_psi"][0].to_value(u.day)  # they do vary


def test_classify_rows_masks_the_periods_of_principal_axis_rows_and_reclassifies(tmp_path):
    """PA rows keep P_sid and lose the P_ψ/P_φ split (masked, empty in ECSV and CSV); a new threshold re-classifies."""
    from astropy.table import QTable

    from spinorbit.spin_forms import SpinFormError
    from spinorbit.state_table import classify_rows

    body = RigidBody([1.0, 1.2, 1.5])
    tilts = np.radians([0.0, 1e-6, 0.5, 3.0])  # wobble amplitudes 0, 1.4e-6°, 0.707°, 4.24° (× √2 along x)
    omegas = np.stack([np.sin(tilts), np.zeros(4), 1.5 * np.cos(tilts)], axis=1) / body.moment_values * 3.0
    table = QTable(table_columns(body, np.tile([1.0, 0, 0, 0], (4, 1)), omegas, motion="rows"))
    classify_rows(table)
    assert list(table["rotation_class"]) == ["PA", "PA", "PA", "SAM"] and table.meta["pa_threshold"] == "1 deg"
    assert table.colnames[-2:] == ["wobble_amplitude", "rotation_class"]
    assert list(table["P_psi"].mask) == list(table["P_phi"].mask) == [True, True, True, False]
    tumbler = RotationState(body, [1.0, 0, 0, 0], omegas[3] * u.rad / u.day)
    assert table["P_psi"][3] == tumbler.periods[0].to(u.h) and table["P_phi"][3] == tumbler.periods[1].to(u.h)
    for path in (tmp_path / "t.ecsv", tmp_path / "t.csv"):
        table.write(path)
        back = QTable.read(path)
        assert list(np.ma.getmaskarray(back["P_psi"])) == [True, True, True, False]
        assert list(back["rotation_class"]) == ["PA", "PA", "PA", "SAM"]
    classify_rows(table, 0.1 * u.deg)  # the values stay under the mask: a smaller threshold brings them back
    assert list(table["rotation_class"]) == ["PA", "PA", "SAM", "SAM"]
    assert list(table["P_psi"].mask) == [True, True, False, False] and table.meta["pa_threshold"] == "0.1 deg"
    classify_rows(table, 0 * u.deg)
    assert list(table["rotation_class"]) == ["PA", "SAM", "SAM", "SAM"]  # 1e-6° of wobble is a SAM at 0°
    with pytest.raises(SpinFormError, match="pa_threshold expects a wobble amplitude in"):
        classify_rows(table, 90 * u.deg)
