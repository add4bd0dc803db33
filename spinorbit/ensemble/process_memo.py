"""What a process keeps across the ensemble chunks it runs: its samplings of an orbit and its leader plans.

Both are pure functions of their keys (exact sampling requests; the leader's parameters), so a kept
entry is the bits a fresh one gives, and a chunk's numbers do not depend on which chunks ran before it
in the same process (``docs/ensembles.md``).
"""

from __future__ import annotations

__all__ = ["clear_process_samplings", "leader_plan", "process_memo", "sharing_key"]


def sharing_key(scene):
    """Members with the same orbit object, span, user ephemerides and sample tolerance sample once."""
    return (id(scene.orbit), float(scene.epoch_day), float(scene.output_days[-1]),
            tuple(id(p) for p in scene.moving), scene.sample_tolerance)


#: Most sharing keys whose samplings a worker process keeps across chunks (an ensemble has one or a few).
MEMO_KEYS = 8
#: {sharing key: (orbit, moving perturbers, memo)}: this process's samplings, kept across chunks. The
#: orbit and ephemerides are held, so the ids in the key stay theirs while the entry lives.
_PROCESS_SAMPLINGS = {}


def process_memo(scene):
    """The memo of this process's samplings for the scene's orbit, span and ephemerides (SharedSamples(memo))."""
    key = sharing_key(scene)
    entry = _PROCESS_SAMPLINGS.get(key)
    if entry is None or entry[0] is not scene.orbit:
        if len(_PROCESS_SAMPLINGS) >= MEMO_KEYS:
            _PROCESS_SAMPLINGS.pop(next(iter(_PROCESS_SAMPLINGS)))
        entry = _PROCESS_SAMPLINGS[key] = (scene.orbit, tuple(scene.moving), {})
    return entry[2]


#: Most ensemble leaders whose group plans a process keeps across chunks (one per ensemble run in it).
LEADER_KEYS = 4
#: {(make_scene, the leader's parameters as fingerprint text): (leader's keys, GroupPlan or None)}: the group
#: plan of an ensemble's leader in this process, made once and taken by every chunk whose group it fits.
_PROCESS_LEADERS = {}


def clear_process_samplings():
    """Forget the samplings and leader plans this process keeps across chunks (e.g. after changing an orbit)."""
    _PROCESS_SAMPLINGS.clear()
    _PROCESS_LEADERS.clear()


def leader_plan(make_scene, leader, at_days, samples_of, integrators, build, text):
    """((sharing key, group key), GroupPlan or None) of the ensemble's leader ``(index, parameters)`` in this
    process (planned once: :func:`~spinorbit.ensemble.batch.plan_group`), or None when it cannot lead a
    group (it fails to build, or cannot be batched). ``build(make_scene, parameters)`` builds a member,
    ``text`` is the leader's parameters as fingerprint text (what, with make_scene, names it); both are
    passed in because :mod:`spinorbit.ensemble.ensemble`, which defines them, imports this module."""
    from spinorbit.ensemble.batch import group_key, plan_group

    token = (make_scene, text, None if at_days is None else at_days.tobytes(),
             tuple(sorted(integrators.items())) if integrators else None)
    if token not in _PROCESS_LEADERS:
        try:
            scene = build(make_scene, leader[1])
        except Exception:  # noqa: BLE001 — the leader's failure is recorded where it runs as a member
            scene = None
        key = None if scene is None else group_key(scene, at_days)
        entry = None if key is None else ((sharing_key(scene), key),
                                          plan_group(scene, samples_of(scene), integrators))
        if len(_PROCESS_LEADERS) >= LEADER_KEYS:
            _PROCESS_LEADERS.pop(next(iter(_PROCESS_LEADERS)))
        _PROCESS_LEADERS[token] = entry
    return _PROCESS_LEADERS[token]
