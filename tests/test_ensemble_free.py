"""Torque-free members in one vectorised call: the same bits alone, in any batch, and through the Ensemble.

The independent checks: the members' own Scenes (another route: RotationState's scalar properties
and the Scene's torque-free run) and RotationState.propagate_torque_free for the attitudes.
"""

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.scene import Scene
from spinorbit.ensemble import Ensemble, EnsembleError, free_members_table, state_at_phase

EPOCH = Time("2029-04-08T00:00:00", scale="tdb")
N = 40


def _members(n=N, seed=3):
    """Moments A ≤ B ≤ C (a few axisymmetric: the closed-form branch), random attitudes and spins (SAM and LAM)."""
    rng = np.random.default_rng(seed)
    moments = np.stack([rng.uniform(0.5, 0.9, n), rng.uniform(0.9, 0.99, n), np.ones(n)], axis=1)
    moments[:3, 1] = moments[:3, 0]  # A = B: regular precession
    quaternions = rng.normal(size=(n, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    return moments, quaternions, rng.normal(size=(n, 3)) * 2.0 * u.rad / u.day


def _bits(table, name):
    values = np.asarray(getattr(table[name], "value", table[name]))
    return "".join(f"{v}|" for v in values.tolist()).encode() if values.dtype.kind == "U" else values.tobytes()


def _state(moments, quaternion, omega):
    return RotationState(RigidBody(moments), quaternion, omega)


@pytest.mark.parametrize("attitudes", [False, True])
def test_a_member_alone_and_in_any_batch_gives_the_same_bits(attitudes):
    moments, quaternions, omegas = _members()
    times = [0.5, 3.0] * u.day
    batch = free_members_table(moments, quaternions, omegas, times, attitudes=attitudes)
    assert set(batch["mode_t0"]) == {"SAM", "LAM"}
    halves = [free_members_table(moments[s], quaternions[s], omegas[s], times, attitudes=attitudes)
              for s in (slice(0, 17), slice(17, N))]
    for name in batch.colnames:
        alone = b"".join(_bits(free_members_table(moments[i:i + 1], quaternions[i:i + 1], omegas[i:i + 1], times,
                                                  attitudes=attitudes), name) for i in range(N))
        assert _bits(batch, name) == alone == b"".join(_bits(h, name) for h in halves), name


def test_the_attitudes_are_the_exact_flow_and_the_pole_does_not_move():
    moments, quaternions, omegas = _members(8)
    table = free_members_table(moments, quaternions, omegas, [2.0, 40.0] * u.day, attitudes=True)
    for i in range(8):
        state = _state(moments[i], quaternions[i], omegas[i])
        flowed, _ = state.propagate_torque_free([2.0, 40.0] * u.day)
        for k in range(2):
            q = np.array([table[f"{c}_t{k}"][i] for c in ("q_w", "q_x", "q_y", "q_z")])
            # the same attitude (q and −q are one): 1e-14 covers a few ulps of the flow's output
            assert min(np.abs(q - flowed[k]).max(), np.abs(q + flowed[k]).max()) < 1e-14
            assert table[f"pole_shift_t{k}"][i].to_value(u.deg) < 1e-11  # the momentum is fixed in free rotation
        ra, dec = state.pole_icrf
        assert table["pole_ra_t1"][i].to_value(u.deg) == pytest.approx(ra.to_value(u.deg), abs=1e-10)
        assert table["pole_dec_t1"][i].to_value(u.deg) == pytest.approx(dec.to_value(u.deg), abs=1e-10)


def _free_member(i, seed=3):
    moments, quaternions, omegas = _members(seed=seed)
    return Scene(_state(moments[i], quaternions[i], omegas[i]), EPOCH, EPOCH + [1.0, 3.0] * u.day)


def test_the_ensemble_of_scenes_gives_the_vectorised_bits_and_agrees_with_each_scene():
    moments, quaternions, omegas = _members()
    ensemble = Ensemble(_free_member, [dict(i=i) for i in range(N)], chunk_size=7)
    table = ensemble.run(executor="serial")
    assert ensemble.last_run["members_in_process"] == N
    # the states as the Scenes hold them (RotationState normalises its quaternion)
    states = [_state(moments[i], quaternions[i], omegas[i]) for i in range(N)]
    vectorised = free_members_table(moments, [s.quaternion for s in states],
                                    np.array([s.angular_velocity.value for s in states]) * u.rad / u.day, 3.0 * u.day)
    for name in vectorised.colnames:
        assert _bits(table, name) == _bits(vectorised, name), name
    for i in (0, 5, 33):  # the member's own Scene run: its scalar properties and its end pole
        alone = _free_member(i).run().table
        assert table["mode"][i] == alone["mode"][-1]
        for name in ("energy_ratio", "P_psi", "P_phi", "sidereal_period"):
            assert u.Quantity(table[name][i]).value == pytest.approx(u.Quantity(alone[name][-1]).value, rel=1e-13)
        for name in ("pole_ra", "pole_dec", "pole_lon", "pole_lat"):
            assert table[name][i].to_value(u.deg) == pytest.approx(alone[name][-1].to_value(u.deg), abs=1e-10)


def test_named_times_and_members_of_other_epochs():
    def member(phase, late):
        state = state_at_phase(RotationState(RigidBody([0.61, 0.965, 1.0]), [1.0, 0.0, 0.0, 0.0], [0.3, 0.1, 2.0] * u.rad / u.day), phase)
        epoch = EPOCH + (0.5 * u.day if late else 0.0 * u.day)
        return Scene(state, epoch, EPOCH + [1.0, 2.0] * u.day)

    params = [dict(phase=p, late=bool(k % 2)) for k, p in enumerate((0.0, 0.2, 0.4, 0.6))]
    table = Ensemble(member, params, at=EPOCH + [1.0, 2.0] * u.day).run(executor="serial")
    assert "P_psi_t1" in table.colnames and set(table["route"]) == {"torque-free"}
    assert np.all(table["pole_shift_t0"] == 0.0 * u.deg)
    first = member(0.2, True).state
    assert table["P_psi_t0"][1].to_value(u.h) == pytest.approx(first.periods[0].to_value(u.h), rel=1e-13)


def test_bad_members_are_refused_with_the_reason():
    moments, quaternions, omegas = _members(2)
    with pytest.raises(EnsembleError, match="0 < A ≤ B ≤ C"):
        free_members_table(moments[:, ::-1], quaternions, omegas, 1.0 * u.day)
    with pytest.raises(EnsembleError, match="row 1 is zero"):
        free_members_table(moments, quaternions, [[1.0, 0, 0], [0, 0, 0]] * u.rad / u.day, 1.0 * u.day)
    with pytest.raises(EnsembleError, match="unit rows"):
        free_members_table(moments, 2 * quaternions, omegas, 1.0 * u.day)
    with pytest.raises(EnsembleError, match=r"shape \(2, 3\)"):
        free_members_table(moments, quaternions, omegas[:1], 1.0 * u.day)
    with pytest.raises(EnsembleError, match="finite"):
        free_members_table(moments, quaternions, omegas, [1.0, np.nan] * u.day)
    with pytest.raises(EnsembleError, match="beyond the free flow's domain"):
        free_members_table(moments, quaternions, omegas, 1e16 * u.day, attitudes=True)


def _permuted_member(phase):
    """A body whose axes are not its principal axes in increasing order (C, A, B along x, y, z)."""
    body = RigidBody([1.0, 0.61, 0.965])
    return Scene(state_at_phase(RotationState(body, [1.0, 0.0, 0.0, 0.0], [2.0, 0.3, 0.1] * u.rad / u.day), phase), EPOCH,
                 EPOCH + 2.0 * u.day)


def test_a_body_off_its_principal_order_is_turned_to_it_and_agrees_with_its_scene():
    table = Ensemble(_permuted_member, [dict(phase=p) for p in (0.0, 0.3, 0.7)]).run(executor="serial")
    for i, phase in enumerate((0.0, 0.3, 0.7)):
        alone = _permuted_member(phase).run().table
        assert table["mode"][i] == alone["mode"][-1] == "SAM"
        for name in ("energy_ratio", "P_psi", "P_phi", "sidereal_period"):
            assert u.Quantity(table[name][i]).value == pytest.approx(u.Quantity(alone[name][-1]).value, rel=1e-13)
        for name in ("pole_ra", "pole_dec", "pole_lon", "pole_lat"):
            assert table[name][i].to_value(u.deg) == pytest.approx(alone[name][-1].to_value(u.deg), abs=1e-10)
