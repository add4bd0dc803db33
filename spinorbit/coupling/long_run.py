"""A coupled run to a list of output times that can be interrupted and resumed bit for bit.

The run is a sequence of chunks: chunk i integrates orbits and rotation from ``times[i-1]`` to
``times[i]`` with ``exact_finish_time = 1`` and records one row (e.g. the quaternion). An
uninterrupted run and a resumed one take *the same chunks*, and a chunk's result depends only on the
simulation's binary state at its start (particles, ``t``, ``dt``, the BS controller's flags) and on
the rotation state — exactly what :meth:`CoupledRigidBody.checkpoint` stores. Hence the resumed run
ends with the same bits (``tests/test_checkpoint_runs.py`` checks it across processes).

The checkpoint holds the body's checkpoint, the rows done so far, the chunk count, a fingerprint of
the output times and the caller's settings; a resume with other times or settings is refused.
:func:`coupled_run` is the short form the scene planner uses: the fully coupled rotation of a body at
output times, on a copy of a simulation, without checkpoints. :func:`integrate_step_ends` is the
other route, without checkpoints: BS's natural steps, each step end kept, outputs interpolated
afterwards (:mod:`spinorbit.coupling.dense_output`), so outputs closer than a step cut none.
"""

from __future__ import annotations

import json
import time as _time

import numpy as np

from spinorbit.core.model.gravity_field import make_body
from spinorbit.coupling.rebound import ROTATION_STATE_SIZE, SimulationSnapshot, body_index, integrate_interruptibly
from spinorbit.coupling.rigid_body import CoupledRigidBody
from spinorbit.runs.checkpoint import Checkpoint, CheckpointSchedule, fingerprint

__all__ = ["CHUNKED_RUN_KIND", "OUTPUT_STEP_GROWTH", "integrate_step_ends", "integrate_to_outputs", "coupled_run",
           "reach_in_one_step"]

#: ``kind`` of the checkpoints written by :func:`integrate_to_outputs`.
CHUNKED_RUN_KIND = "coupled-run"
#: Largest growth of the step that :func:`reach_in_one_step` allows from one chunk to the next (a step
#: controller's kind of limit): an output at most this many last steps away is reached in one step.
OUTPUT_STEP_GROWTH = 2.0


def reach_in_one_step(sim, target) -> None:
    """Let the next chunk reach ``target`` in one step when it is at most OUTPUT_STEP_GROWTH steps away.

    With ``exact_finish_time`` REBOUND shortens the step that would pass the output, then restores
    ``dt`` to the last *full* step, so the step controller's proposal after the shortened one is lost.
    With outputs closer than the natural step, every chunk then becomes one full step plus one
    shortened step and ``dt`` never grows again: the Moon (natural BS step ≈ 6 d) took 735 steps a year
    for daily outputs, against 72 without them. Growing ``dt`` up to the output, by at most
    OUTPUT_STEP_GROWTH a chunk, makes each chunk one step; BS still rejects and shortens a step its
    error control does not accept, and outputs farther away than that are left to the controller.
    ``sim.t`` and ``sim.dt`` are in a checkpoint, so a resumed run takes the same steps.
    """
    remaining = target - sim.t
    if sim.dt * remaining > 0.0 and abs(sim.dt) < abs(remaining) <= OUTPUT_STEP_GROWTH * abs(sim.dt):
        sim.dt = remaining


def _summary(times) -> str:
    """Readable description of output times for error messages (the fingerprint decides)."""
    return f"{times.size} times from {times[0]!r} to {times[-1]!r}" if times.size else "no times"


def integrate_to_outputs(body, times, record, row_size: int, schedule: CheckpointSchedule | None = None,
                         resume=None, settings: dict | None = None, progress=None):
    """Integrate ``body`` to each of ``times`` and record ``record(body)`` there; checkpoint as scheduled.

    Parameters
    ----------
    body : CoupledRigidBody or None
        The run's start (``body.sim.t`` ≤ ``times[0]``). Ignored (may be None) when resuming: the
        checkpoint holds the body.
    times : array_like, shape (n,)
        Output times (simulation time units, increasing); each is one chunk.
    record : callable
        ``record(body) -> array of row_size floats`` at each output time.
    row_size : int
        Length of a recorded row.
    schedule : spinorbit.runs.checkpoint.CheckpointSchedule, optional
        When and where to write checkpoints (none if omitted).
    resume : str or os.PathLike, optional
        A checkpoint written by this function: the run continues from it.
    settings : dict, optional
        JSON-serialisable description of the run (model, span, ...); stored, and compared on resume.
    progress : callable, optional
        Called with the number of output times done.

    Returns
    -------
    body : CoupledRigidBody
        At ``times[-1]`` (the resumed body when resuming).
    rows : ndarray, shape (n, row_size)
    wall_seconds : float
        Wall time spent integrating, over all the pieces of an interrupted run.

    Raises
    ------
    spinorbit.runs.checkpoint.CheckpointError
        ``resume`` is unreadable, truncated, corrupted, or from a run with other times or settings.
    spinorbit.runs.checkpoint.RunStopped
        The schedule's ``stop_after_chunks`` was reached (after writing the checkpoint).
    """
    times = np.asarray(times, dtype=float)
    settings = json.loads(json.dumps({} if settings is None else settings))  # as it reads back
    times_id = fingerprint(times)
    rows = np.full((times.size, int(row_size)), np.nan)
    done, wall = 0, 0.0
    if resume is not None:
        checkpoint = Checkpoint.read(resume, kind=CHUNKED_RUN_KIND)
        checkpoint.expect(resume, "settings", checkpoint.setting(resume, "settings", dict), settings)
        if checkpoint.setting(resume, "times", str) != times_id:  # the summary may coincide; the fingerprint decides
            checkpoint.expect(resume, "output times", f"{checkpoint.meta['times_summary']} (SHA-256 "
                              f"{checkpoint.meta['times'][:12]}…)", f"{_summary(times)} (SHA-256 {times_id[:12]}…)")
        body_part = Checkpoint(kind="", arrays={k.removeprefix("body."): v for k, v in checkpoint.arrays.items()
                                                if k.startswith("body.")}, meta=checkpoint.meta["body"])
        body = CoupledRigidBody.from_checkpoint(body_part)
        done, wall = checkpoint.setting(resume, "done", int), checkpoint.setting(resume, "wall_seconds", float)
        if not 0 < done < times.size:
            checkpoint.expect(resume, "number of output times done", done, f"1 to {times.size - 1}")
        rows[:done] = checkpoint.array(resume, "rows", np.float64, (done, rows.shape[1]))
        if progress is not None:
            progress(done)
    for i in range(done, times.size):
        begin = _time.perf_counter()
        reach_in_one_step(body.sim, times[i])
        body.integrate(times[i])
        wall += _time.perf_counter() - begin
        rows[i] = record(body)
        if progress is not None:
            progress(i + 1)
        if schedule is not None and i + 1 < times.size and schedule.due(i + 1):
            body_checkpoint = body.checkpoint()
            arrays = {f"body.{k}": v for k, v in body_checkpoint.arrays.items()}
            arrays["rows"] = rows[:i + 1]
            schedule.write(Checkpoint(kind=CHUNKED_RUN_KIND, arrays=arrays, meta={
                "body": body_checkpoint.meta, "done": i + 1, "times": times_id, "times_summary": _summary(times),
                "settings": settings,
                "wall_seconds": wall}), i + 1)
    return body, rows, wall


def integrate_step_ends(body, end, times=None, progress=None):
    """Integrate ``body`` to ``end`` in BS's natural steps and keep the state at every step end.

    No output time cuts a step: only the last chunk ends at ``end`` (``exact_finish_time``), so
    outputs come from the step ends by interpolation (:mod:`spinorbit.coupling.dense_output`).
    Not resumable from a checkpoint (use :func:`integrate_to_outputs` for that).

    Parameters
    ----------
    body : CoupledRigidBody
        At its start (``body.sim.t`` < ``end``, integrating forwards).
    end : float
        Final time (simulation units).
    times : ndarray, optional
        Output times, for ``progress`` only.
    progress : callable, optional
        Called after each step with the number of ``times`` reached.

    Returns
    -------
    node_times : ndarray, shape (n,)
        The start, every step end, and ``end``.
    node_states : ndarray, shape (n, 7)
        ``body.state`` there.
    wall_seconds : float
        Wall time spent integrating.
    """
    sim = body.sim
    if not end > sim.t:
        raise ValueError(f"integrate_step_ends: expected end > sim.t = {sim.t!r} (forwards), got {end!r}.")
    node_times, node_states = [sim.t], [body.state]
    wall = 0.0
    sim.exact_finish_time = 1
    while True:
        begin = _time.perf_counter()
        last = sim.t + sim.dt >= end  # the next step would pass the end: finish there exactly
        body.integrate(end) if last else body.step()
        wall += _time.perf_counter() - begin
        if sim.t == node_times[-1]:
            continue  # a step BS rejected: t did not move, so there is no new step end
        node_times.append(sim.t)
        node_states.append(body.state)
        if progress is not None and times is not None:
            progress(int(np.searchsorted(times, sim.t, side="right")))
        if last:
            break
    return np.array(node_times), np.array(node_states), wall


def coupled_run(sim, body, moments_per_mass, state, start, times, perturbers, tolerance):
    """The fully coupled rotation of ``body`` at ``times``, on a copy of ``sim`` (``sim`` is not modified).

    The copy (particles, G, integrator, extra forces reinstalled, as the one-way sampler rebuilds it)
    is first carried to ``start`` by its own integrator with point masses — the orbits the one-way
    route samples — then switched to BS (the only integrator that couples a user ODE,
    ``docs/coupling.md``) with the rotation attached, ``coupled=True``, and integrated through
    ``times`` with ``exact_finish_time``.

    Parameters
    ----------
    sim : rebound.Simulation
        ("AU", "day", "Msun") units, ``t`` in TDB days since J2000 (e.g. ``simulation_from_de421``).
    body : str
        Particle with the figure; it must have mass.
    moments_per_mass : (A, B, C)
        Principal moments over the body's mass, au² (degree-2 figure; times the particle's mass it is
        the figure in the simulation's units).
    state : array_like, shape (7,)
        (q, ω) at ``start``: q principal axes → ICRF (scalar first), ω principal axes, rad/day.
    start : float
        TDB days since J2000.
    times : ndarray
        Output times after ``start``, increasing, TDB days since J2000.
    perturbers : sequence of str
        Particles that torque the figure and feel its back-reaction.
    tolerance : float
        BS eps_abs = eps_rel.

    Returns
    -------
    states : ndarray, shape (n, 7)
        (q, ω) at ``times``, same axes as ``state``.
    stats : dict
        ``steps`` (BS steps taken, REBOUND's ``steps_done``), ``wall_seconds`` (integration only).
    """
    copy = SimulationSnapshot.of(sim).build()
    integrate_interruptibly(copy, start)
    copy.integrator = "bs"
    copy.integrator.eps_abs = tolerance
    copy.integrator.eps_rel = tolerance
    mass = copy.particles[body_index(copy, body)].m
    figure = make_body(tuple(float(m) * mass for m in moments_per_mass), mass=mass)
    rigid = CoupledRigidBody(copy, body, figure, state, perturbers=perturbers, coupled=True)
    steps = copy.steps_done
    _, rows, wall = integrate_to_outputs(rigid, times, lambda b: b.state, ROTATION_STATE_SIZE)
    return rows, {"steps": int(copy.steps_done - steps), "wall_seconds": wall}
