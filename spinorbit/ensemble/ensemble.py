"""An ensemble of Scenes: one member per parameter row, run in fixed chunks on any executor, one outcome table.

A member is a :class:`~spinorbit.scene.Scene` built by ``make_scene(**parameters)`` from one row of
the parameter table (``docs/ensembles.md``), or a member that runs itself
(:mod:`~spinorbit.ensemble.self_run`): same chunks, executors, checkpoints and reruns. The members are
cut into chunks of consecutive indices whose size depends on the ensemble alone (its member count, or ``chunk_size``), never on the
executor or the number of workers; a chunk runs in one process, its members sharing the perturber
samples of one orbit (:meth:`Scene.sharing_samples`), so the table is the same bits whichever
executor ran it. A worker builds its members' Scenes itself: only ``make_scene`` (as bytes it loads
itself, :mod:`~spinorbit.ensemble.shipping`) and the parameter rows travel, and each member is built
once, where it runs; a worker keeps its samplings of an orbit across the chunks it runs (exact requests only, so
the numbers do not depend on which chunks it ran). Members with no perturbers and no orbit need no
integration: their outcomes come from one vectorised call per chunk
(:func:`~spinorbit.ensemble.free.torque_free_rows`), in this process when the first member is
torque-free (then they are not shipped).

Completed chunks are checkpointed (:class:`~spinorbit.ensemble.store.ChunkStore`); a resumed run
runs only the chunks without a file. A member that raises is recorded (index, parameters, exception
type and message), its row masked, and :meth:`Ensemble.rerun` runs it again alone.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import math
import time as _time

import numpy as np
from astropy.table import Column, MaskedColumn
from astropy.utils.masked import Masked

from spinorbit.ensemble.errors import EnsembleError, EnsembleInterrupted
from spinorbit.ensemble.executors import open_executor, owns_workers
from spinorbit.ensemble.outcomes import (
    INITIAL_COLUMNS,
    OUTCOME_UNITS,
    RUN_COLUMNS,
    TIMED_COLUMNS,
    days_of,
    outcome_row,
)
from spinorbit.ensemble.free import torque_free_rows
from spinorbit.ensemble.parameters import parameter_table, plain_value
from spinorbit.ensemble.identity import ensemble_fingerprint, ensemble_identity, value_text
from spinorbit.ensemble.process_memo import clear_process_samplings, leader_plan, process_memo, sharing_key
from spinorbit.ensemble.samplers import SEED_COLUMNS, sample_parameters
from spinorbit.ensemble.shipping import load_where_run, shipped_for
from spinorbit.ensemble.self_run import checked_units, own_columns, own_row, runs_itself
from spinorbit.ensemble.store import ChunkStore

__all__ = ["ROUTES", "Ensemble", "run_chunk", "torque_free"]

#: Most members in a default chunk; the default is ceil(n / 32) up to this (chunks few enough to
#: spread over many workers, large enough that a chunk's shared sampling pays).
MAX_DEFAULT_CHUNK = 16
#: With the batch route a chunk's group is integrated in one call per attempt and takes the plan its
#: process made once, so its default chunks are ceil(n / BATCH_CHUNKS) members, at most MAX_BATCH_CHUNK:
#: 8 chunks, not fewer, so that members of unequal cost (their retries) still share 2 workers evenly
#: at the end of the run (benchmarks/bench_ensemble.py's parallel efficiency).
BATCH_CHUNKS = 8
MAX_BATCH_CHUNK = 64


def build_member(make_scene, parameters):
    """The member of one row: a single-body Scene or a member that runs itself (:func:`runs_itself`);
    EnsembleError when make_scene returns something else."""
    from spinorbit.scene import Scene

    scene = make_scene(**parameters)
    if runs_itself(scene):
        return scene
    if not isinstance(scene, Scene) or scene.members is not None:
        raise EnsembleError(f"make_scene expects to return a single-body spinorbit.scene.Scene or a member with an "
                            f"outcome_row(at_days) method; it returned "
                            f"{type(scene).__name__}{' of several bodies' if isinstance(scene, Scene) else ''}.")
    return scene


def failure_record(index, parameters, error):
    """What a failed member leaves: index, parameters (repr), exception type and message (JSON-ready)."""
    return {"index": int(index), "parameters": {k: repr(v) for k, v in parameters.items()},
            "type": type(error).__name__, "message": str(error)}


def torque_free(scene):
    """The member needs no integration: a Scene with no perturbers and no orbit."""
    if runs_itself(scene):
        return False
    return not scene.named and not scene.fixed and not scene.moving and scene.orbit is None


def free_rows(free, at_days, rows, failures):
    """Add to ``rows`` the outcome rows of torque-free members ``free`` [(index, Scene, parameters)] (one
    vectorised call), or to ``failures`` a record for each of them if that call raises."""
    if not free:
        return
    try:
        rows.update((i, {**row, "ensemble_route": "torque-free"})
                    for (i, _, _), row in zip(free, torque_free_rows([s for _, s, _ in free], at_days)))
    except Exception as error:  # noqa: BLE001 — recorded like a worker's failure
        failures.update({i: failure_record(i, p, error) for i, _, p in free})


#: The ensemble's routes: "auto" plans the members that can share a plan as groups and integrates each
#: group together (:mod:`spinorbit.ensemble.batch`), the rest through their own Scene; "member" runs
#: every member through its own Scene.
ROUTES = ("auto", "member")


def run_chunk(make_scene, members, at_days=None, keep_tables=False, scenes=None, route="auto", integrators=None,
              leader=None):
    """Run one chunk of members in this process (what a worker does): (rows, failures, tables).

    ``members`` is a list of (index, parameter dict); ``scenes`` optionally ``{index: Scene}`` of
    members already built in this process (each member is built once, where it runs). Rows and
    failures are dicts by index, tables the members' result tables when ``keep_tables``.

    Members of one orbit, span and ephemerides share their perturber samples: within the chunk
    (:meth:`Scene.sharing_samples`), and across the chunks this process runs through an exact-request
    memo (:class:`~spinorbit.scene.sampling.SharedSamples`), so a worker samples the orbit once, and
    every chunk's numbers are those it gives alone. Torque-free members (unless ``keep_tables``) take
    one vectorised call for the chunk (:func:`~spinorbit.ensemble.free.torque_free_rows`; the same
    bits in any process or batch). With ``route="auto"`` (and no tables kept) the members that can
    share a plan run as groups by the batch route (:func:`spinorbit.ensemble.batch.run_group`, its
    batch integrators ``integrators``, default :data:`~spinorbit.ensemble.batch.BATCH_INTEGRATORS`);
    every row records its route in ``ensemble_route`` ("batch", "scene", "torque-free", or "self-run" for a
    member that runs itself). A group
    takes the plan of ``leader`` (the ensemble's (index, parameters) whose plan leads, planned once
    per process) when the leader would be in it, else its first member's; the members the leader's
    plan does not fit (its drops) are led by the first of them.
    """
    from spinorbit.ensemble.batch import group_key, plan_group, run_group
    from spinorbit.scene.sampling import SharedSamples

    make_scene, unloaded = load_where_run(make_scene, members)  # sent as bytes (shipping.py): loaded here
    if unloaded:  # it could not be: every member fails with that cause
        return {}, unloaded, {}
    rows, failures, tables, shared, free, built = {}, {}, {}, {}, [], []
    scenes = scenes or {}
    for index, parameters in members:
        try:
            scene = scenes[index] if index in scenes else build_member(make_scene, parameters)
        except Exception as error:  # noqa: BLE001 — a member's failure is recorded, the chunk goes on
            failures[index] = failure_record(index, parameters, error)
            continue
        if not keep_tables and torque_free(scene):
            free.append((index, scene, parameters))
        else:
            built.append((index, scene, parameters))

    def samples_of(scene):
        # the scene stays referenced with its samples, so an id() in the key is never reused in the chunk
        return shared.setdefault(sharing_key(scene), (scene, SharedSamples(process_memo(scene))))[1]

    single = built
    if route == "auto" and not keep_tables:
        groups, single = {}, []
        for member in built:
            key = None if runs_itself(member[1]) else group_key(member[1], at_days)
            (single.append(member) if key is None else
             groups.setdefault((sharing_key(member[1]), key), []).append(member))
        led = None
        if leader is not None and groups:
            text = "|".join(f"{name}={value_text(value)}" for name, value in leader[1].items())
            led = leader_plan(make_scene, leader, at_days, samples_of, integrators, build_member, text)
        for keys, group in groups.items():
            # the ensemble leader's plan where it fits the group (and could be made), else the first member's
            group_plan = led[1] if led is not None and keys == led[0] else None
            led_by_ensemble = group_plan is not None
            if group_plan is None:
                group_plan = plan_group(group[0][1], samples_of(group[0][1]), integrators)
            if group_plan is None:  # no plan to share: every member through its own Scene
                single.extend(group)
                continue
            group_rows, group_failures, fallback = run_group(group, group_plan, at_days, integrators)
            if led_by_ensemble and len(fallback) > 1:  # those the ensemble's plan does not fit: led by their first
                second = plan_group(fallback[0][1], samples_of(fallback[0][1]), integrators)
                if second is not None:
                    more_rows, more_failures, fallback = run_group(fallback, second, at_days, integrators)
                    group_rows.update(more_rows)
                    group_failures.update(more_failures)
            rows.update({i: {**row, "ensemble_route": "batch"} for i, row in group_rows.items()})
            failures.update({i: failure_record(i, p, group_failures[i]) for i, _, p in group if i in group_failures})
            single.extend(fallback)
        single.sort(key=lambda member: member[0])
    for index, scene, parameters in single:
        try:
            if runs_itself(scene):
                rows[index] = {**own_row(scene, at_days), "ensemble_route": "self-run"}
                continue
            with scene.sharing_samples(samples_of(scene)):
                result = scene.run()
            rows[index] = {**outcome_row(scene, result, at_days), "ensemble_route": "scene"}
            if keep_tables:
                tables[index] = result.table
        except Exception as error:  # noqa: BLE001 — a member's failure is recorded, the chunk goes on
            failures[index] = failure_record(index, parameters, error)
    free_rows(free, at_days, rows, failures)
    return rows, failures, tables


class Ensemble:
    """Members built by ``make_scene(**row)`` from a table of parameters, run in fixed chunks on any executor.

    Parameters
    ----------
    make_scene : callable
        ``make_scene(**parameters) -> Scene`` (one body), or a member that runs itself (an object with
        ``outcome_row(at_days) -> dict``, module docstring). A module-level function, so that worker
        processes can import it; an expensive orbit it needs should be cached in its module
        (e.g. ``functools.cache``), so each process builds it once and members share its samples.
        Each member is built once, where its chunk runs. On an executor, this process builds the
        first member too, to see whether the members are torque-free; if it is, every member is
        built here, and the torque-free ones are not shipped (so this process may build the cached
        orbit once too).
    parameters : QTable or list of dict
        One row per member; the columns are make_scene's keyword arguments (except the seed columns
        ``seed_entropy`` and ``seed_spawn_key`` of :func:`~spinorbit.ensemble.samplers.sample_parameters`,
        which are recorded, not passed).
    chunk_size : int, optional
        Members per chunk; default ``min(64, ceil(n / 8))`` with ``route="auto"`` (a chunk's group
        shares a plan), ``min(16, ceil(n / 32))`` with ``route="member"``. It fixes the work units, so
        results do not depend on the executor or the number of workers.
    at : astropy.time.Time, optional
        Times (among every member's output times) at which to report the outcome; default the last
        output time. With ``at`` the time-dependent columns are suffixed ``_t0``, ``_t1``, …
    route : {"auto", "member"}
        "auto": the members of a chunk that can share a plan (:func:`~spinorbit.ensemble.batch.group_key`)
        are planned as a group and integrated together at the core, with no result table per member
        (:mod:`spinorbit.ensemble.batch`); the others, and every member with ``keep_tables``, run
        through their own Scene. "member": every member through its own Scene. The table's
        ``meta["member_routes"]`` counts the members of each route.
    batch_integrators : dict, optional
        ``{plan integrator name: function}`` of the batch route, each with
        :func:`~spinorbit.core.integrators.batch_quaternion.integrate_quaternion_batch`'s signature
        (module-level, so that workers can import it); default
        :data:`~spinorbit.ensemble.batch.BATCH_INTEGRATORS`.
    outcome_units : dict, optional
        ``{column: astropy unit}`` of the numeric outcome columns of members that run themselves (their
        rows hold plain numbers in these units); columns not named are plain numbers.

    Attributes
    ----------
    failures : list of dict
        Failed members: ``index``, ``parameters`` (repr), ``type`` and ``message`` of the exception.
    member_tables : dict
        ``{index: QTable}`` of the members run with ``keep_tables=True`` in this process's calls.
    last_run : dict
        ``members_run``, ``members_restored``, ``members_in_process``, ``chunks_run``,
        ``wall_seconds`` and ``executor`` of the last :meth:`run` or :meth:`rerun`.
    """

    def __init__(self, make_scene, parameters, chunk_size=None, at=None, route="auto", batch_integrators=None,
                 outcome_units=None):
        if not callable(make_scene):
            raise EnsembleError(f"make_scene expects a callable returning a Scene; got {make_scene!r}.")
        if route not in ROUTES:
            raise EnsembleError(f"route expects one of {ROUTES}; got {route!r}. 'auto' batches the members that can "
                                "share a plan, 'member' runs every member through its own Scene.")
        if batch_integrators is not None and not (isinstance(batch_integrators, dict) and all(
                isinstance(k, str) and callable(f) for k, f in batch_integrators.items())):
            raise EnsembleError(f"batch_integrators expects a dict {{plan integrator name: batch function}} (e.g. "
                                f"{{'quaternion': integrate_quaternion_batch}}); got {batch_integrators!r}.")
        self.route, self.batch_integrators = route, batch_integrators
        self.outcome_units = checked_units(outcome_units)
        self.make_scene = make_scene
        self.parameters = parameter_table(parameters)
        n = len(self.parameters)
        if chunk_size is None:
            chunk_size = (min(MAX_BATCH_CHUNK, math.ceil(n / BATCH_CHUNKS)) if route == "auto" else
                          min(MAX_DEFAULT_CHUNK, math.ceil(n / 32)))
        if not (isinstance(chunk_size, (int, np.integer)) and not isinstance(chunk_size, bool) and chunk_size >= 1):
            raise EnsembleError(f"chunk_size expects a positive number of members; got {chunk_size!r}.")
        self.chunk_size = int(chunk_size)
        self.at_days = None if at is None else days_of(at)
        self.at = at
        self._rows, self._failures, self.member_tables, self.last_run = {}, {}, {}, {}
        self._complete = set()  # chunks whose every member has a row or a failure

    @classmethod
    def sampled(cls, make_scene, n, seed=None, chunk_size=None, at=None, route="auto", batch_integrators=None,
                outcome_units=None, **distributions):
        """An ensemble of ``n`` members whose parameters are drawn, each from its own seed
        (:func:`~spinorbit.ensemble.samplers.sample_parameters`; the seeds are columns of the result)."""
        return cls(make_scene, sample_parameters(n, seed, **distributions), chunk_size=chunk_size, at=at, route=route,
                   batch_integrators=batch_integrators, outcome_units=outcome_units)

    # ------------------------------------------------------------------------------------------
    @property
    def n_members(self):
        return len(self.parameters)

    @property
    def n_chunks(self):
        return math.ceil(self.n_members / self.chunk_size)

    def chunk_members(self, chunk):
        return list(range(chunk * self.chunk_size, min((chunk + 1) * self.chunk_size, self.n_members)))

    def member_parameters(self, index):
        """The keyword arguments of make_scene for member ``index`` (the seed columns left out)."""
        row = self.parameters[index]
        return {name: plain_value(row[name]) for name in self.parameters.colnames if name not in SEED_COLUMNS}

    def _plain_columns(self):
        """{name: every member's value as :meth:`member_parameters` gives it}, of every column (seeds too),
        taken column by column once (a table row per member costs more than its member's plan share)."""
        columns = {}
        for name in self.parameters.colnames:
            column = self.parameters[name]
            if type(column) is Column and column.ndim == 1 and column.dtype.kind in "biufU":
                columns[name] = column.tolist()  # numpy's item() of each element, as plain_value takes it
            else:
                columns[name] = [plain_value(column[i]) for i in range(len(column))]
        return columns

    def _members_of(self, indices, columns):
        """[(index, make_scene's keyword arguments)] of ``indices`` from :meth:`_plain_columns`."""
        names = [name for name in columns if name not in SEED_COLUMNS]
        return [(i, {name: columns[name][i] for name in names}) for i in indices]

    @property
    def fingerprint(self):
        """SHA-256 of what fixes the results: make_scene's name, every parameter's bits, chunk size, times
        (:func:`~spinorbit.ensemble.identity.ensemble_fingerprint`)."""
        return ensemble_fingerprint(self, self._plain_columns())

    @property
    def identity(self):
        """The fingerprint's content field by field (:func:`~spinorbit.ensemble.identity.ensemble_identity`),
        kept in a checkpoint directory so that a refusal can say which field differs."""
        return ensemble_identity(self, self._plain_columns())

    def _chunk_store(self, checkpoint):
        """The checkpoint directory taken for this ensemble (locked, its manifest checked), or no store."""
        columns = None if checkpoint is None else self._plain_columns()
        return (contextlib.nullcontext(None) if columns is None else
                ChunkStore(checkpoint, ensemble_fingerprint(self, columns), ensemble_identity(self, columns)))

    @property
    def failures(self):
        return [self._failures[i] for i in sorted(self._failures)]

    # ------------------------------------------------------------------------------------------
    def _restore(self, store):
        restored = 0
        for chunk in range(self.n_chunks):
            if chunk in self._complete:
                continue
            stored = store.read(chunk)
            if stored is not None:
                rows, failures = stored
                self._rows.update(rows)
                self._failures.update(failures)
                self._complete.add(chunk)
                restored += len(self.chunk_members(chunk))
        return restored

    def _split(self, members):
        """(in-process rows, in-process failures, members to run, their Scenes) of [(index, parameters)].

        Every member is built here; the torque-free ones are evaluated at once (one vectorised call),
        the others are returned as (index, parameters) with their Scenes ``{index: Scene}`` (used when
        they run in this process, so that no member is built twice here).
        """
        rows, failures, shipped, scenes = {}, {}, [], {}
        free = []
        for index, parameters in members:
            try:
                scene = build_member(self.make_scene, parameters)
            except Exception as error:  # noqa: BLE001 — recorded like a worker's failure
                failures[index] = failure_record(index, parameters, error)
                continue
            if torque_free(scene):
                free.append((index, scene, parameters))
            else:
                shipped.append((index, parameters))
                scenes[index] = scene
        free_rows(free, self.at_days, rows, failures)
        return rows, failures, shipped, scenes

    def _leader(self):
        """(0, parameters) of the member whose plan its batch groups share (:func:`run_chunk`), or None."""
        return (0, self.member_parameters(0)) if self.route == "auto" else None

    def _first_is_torque_free(self, chunk):
        """Whether the chunk's first member is torque-free (built here once to see; a failure counts as no)."""
        try:
            return torque_free(build_member(self.make_scene, self.member_parameters(self.chunk_members(chunk)[0])))
        except Exception:  # noqa: BLE001 — the member's failure is recorded where it runs
            return False

    def run(self, executor=None, checkpoint=None, progress=None, keep_tables=False):
        """Run every member not yet done (none restored from ``checkpoint``) and return the outcome table.

        Parameters
        ----------
        executor : None, "serial", "dask", int, dask.distributed.Client or concurrent.futures.Executor
            Where the chunks run (:func:`~spinorbit.ensemble.executors.open_executor`).
        checkpoint : path, optional
            Directory of the chunk files: completed chunks are read from it and not run again, and each
            chunk completed now is written there at once (checksummed, atomic).
        progress : callable, optional
            ``progress(members_done, members_total)`` after each completed chunk.
        keep_tables : bool
            Keep every member's full result table in :attr:`member_tables` (the torque-free members
            are then run through their Scene in this process).

        Returns
        -------
        QTable
            :meth:`table`.

        Raises
        ------
        EnsembleInterrupted
            Chunks were lost to the executor (a killed worker, a broken pool); those completed are in
            the checkpoint and in memory: run again (with the same checkpoint) to run only the rest.
        spinorbit.runs.checkpoint.CheckpointError
            ``checkpoint`` holds another ensemble (the message names the fields that differ), is in
            use by another running ensemble, or a file in it is corrupted.
        KeyboardInterrupt
            Ctrl-C (or the CLI's SIGTERM): the chunks not started are cancelled, the workers of an
            executor made here stopped; ``last_run["members_complete"]`` members are kept.
        """
        with self._chunk_store(checkpoint) as store:
            return self._run(store, executor, checkpoint, progress, keep_tables)

    def _run(self, store, executor, checkpoint, progress, keep_tables):
        clock = _time.perf_counter()
        restored = 0 if store is None else self._restore(store)
        pending = [c for c in range(self.n_chunks) if c not in self._complete]
        done = self.n_members - sum(len(self.chunk_members(c)) for c in pending)
        stats = {"members_run": 0, "members_in_process": 0, "members_restored": restored, "chunks_run": 0}
        report = progress or (lambda done, total: None)
        report(done, self.n_members)

        def finish(chunk, rows, failures, tables):
            nonlocal done
            if store is not None:
                store.write(chunk, self.chunk_members(chunk), rows, failures)
            self._rows.update(rows)
            self._failures.update(failures)
            self.member_tables.update(tables)
            self._complete.add(chunk)
            stats["chunks_run"] += 1
            done += len(self.chunk_members(chunk))
            report(done, self.n_members)

        lost, description = {}, str(executor)
        try:
            description = self._run_on(executor, pending, keep_tables, stats, finish, lost)
        except KeyboardInterrupt:  # Ctrl-C or SIGTERM: what finished is kept (checkpointed as it arrived)
            stats.update(wall_seconds=_time.perf_counter() - clock, executor=description, interrupted=True,
                         members_complete=self.members_complete)
            self.last_run = stats
            raise
        stats.update(wall_seconds=_time.perf_counter() - clock, executor=description)
        self.last_run = stats
        if lost:
            members = sum(len(self.chunk_members(c)) for c in lost)
            first = next(iter(lost.values()))
            where = f"in '{checkpoint}'" if checkpoint is not None else "in memory only (no checkpoint given)"
            raise EnsembleInterrupted(
                f"{len(lost)} of {self.n_chunks} chunks ({members} members) did not come back from {description} "
                f"({type(first).__name__}: {first}); the {self.n_members - members} members completed are kept "
                f"{where}. Call run() again (with the same checkpoint) to run only the missing members.",
                members_lost=members, cause=first, executor=description)
        return self.table()

    @property
    def members_complete(self):
        """Members whose chunk is complete (run now or restored): those a resume does not run again."""
        return sum(len(self.chunk_members(c)) for c in self._complete)

    def _run_on(self, executor, pending, keep_tables, stats, finish, lost):
        """Run the ``pending`` chunks on ``executor``, ``finish`` each as it arrives; lost ones into ``lost``.

        Returns the executor's description. A chunk still out when this stops (Ctrl-C) is cancelled,
        and the executor's own workers stopped (:func:`~spinorbit.ensemble.executors.open_executor`).
        """
        with open_executor(executor) as (pool, description):
            # On an executor, the members are built where they run (once each), unless the first member is
            # torque-free: then the members are built here to keep the torque-free ones here (not shipped).
            classify_here = pool is None or (bool(pending) and not keep_tables
                                             and self._first_is_torque_free(pending[0]))
            partial, futures = {}, {}
            shipped = shipped_for(self.make_scene, pool)
            columns = self._plain_columns() if pending else {}
            leader = self._leader()
            for chunk in pending:
                members = self.chunk_members(chunk)
                if keep_tables or not classify_here:
                    rows, failures, ship, scenes = {}, {}, self._members_of(members, columns), {}
                else:
                    rows, failures, ship, scenes = self._split(self._members_of(members, columns))
                stats["members_in_process"] += len(members) - len(ship)
                stats["members_run"] += len(members)
                if not ship:
                    finish(chunk, rows, failures, {})
                elif pool is None:
                    more_rows, more_failures, tables = run_chunk(self.make_scene, ship, self.at_days, keep_tables, scenes,
                                                                 self.route, self.batch_integrators, leader)
                    finish(chunk, {**rows, **more_rows}, {**failures, **more_failures}, tables)
                else:  # submitted at once: the workers start while the next chunks are prepared
                    partial[chunk] = (rows, failures)
                    futures[pool.submit(run_chunk, shipped, ship, self.at_days, keep_tables, None, self.route,
                                        self.batch_integrators, leader)] = chunk
            try:
                for future in concurrent.futures.as_completed(futures):
                    chunk = futures[future]
                    try:
                        rows, failures, tables = future.result()
                    except Exception as error:  # noqa: BLE001 — the executor lost it: kept for the message
                        lost[chunk] = error
                        continue
                    finish(chunk, {**partial[chunk][0], **rows}, {**partial[chunk][1], **failures}, tables)
            except BaseException:  # stopped: a caller's executor keeps running only what had started
                if not owns_workers(executor):  # our own pool is stopped by open_executor (stop_pool)
                    for future in futures:
                        future.cancel()
                raise
        return description

    def rerun(self, indices, executor="serial", checkpoint=None):
        """Run members ``indices`` again, each alone, replace their rows (and failures); return the table.

        Their chunks must be complete (run or restored from ``checkpoint``); with ``checkpoint`` the
        chunk files are rewritten with the new rows.
        """
        with self._chunk_store(checkpoint) as store:
            return self._rerun(store, indices, executor)

    def _rerun(self, store, indices, executor):
        if store is not None:
            self._restore(store)
        indices = sorted({int(i) for i in indices})
        bad = [i for i in indices if not 0 <= i < self.n_members]
        if bad:
            raise EnsembleError(f"rerun expects member indices in [0, {self.n_members}); got {bad}.")
        missing = sorted({i // self.chunk_size for i in indices} - self._complete)
        if missing:
            raise EnsembleError(f"rerun: the chunks {missing} have not run yet; call run() (with the checkpoint) first.")
        clock = _time.perf_counter()
        results, leader = [], self._leader()
        with open_executor(executor) as (pool, description):
            shipped = shipped_for(self.make_scene, pool)
            for index in indices:  # each alone, by the same path as in run(): torque-free ones in this process
                rows, failures, ship, scenes = self._split([(index, self.member_parameters(index))])
                if ship:
                    job = (pool.submit(run_chunk, shipped, ship, self.at_days, False, None, self.route,
                                       self.batch_integrators, leader) if pool is not None else None)
                    rows, failures, _ = (job.result() if job is not None else
                                         run_chunk(self.make_scene, ship, self.at_days, False, scenes, self.route,
                                                   self.batch_integrators, leader))
                results.append((rows, failures, {}))
        for index, (rows, failures, _) in zip(indices, results):
            self._rows.pop(index, None)
            self._failures.pop(index, None)
            self._rows.update(rows)
            self._failures.update(failures)
        if store is not None:
            for chunk in sorted({i // self.chunk_size for i in indices}):
                members = self.chunk_members(chunk)
                store.write(chunk, members, {i: self._rows[i] for i in members if i in self._rows},
                            {i: self._failures[i] for i in members if i in self._failures})
        self.last_run = {"members_run": len(indices), "members_in_process": 0, "members_restored": 0,
                         "chunks_run": len(indices), "wall_seconds": _time.perf_counter() - clock,
                         "executor": description}
        return self.table()

    # ------------------------------------------------------------------------------------------
    def outcome_names(self):
        """Outcome column names in the table's order (those some member has)."""
        timed = [] if self.at_days is None else range(self.at_days.size)
        names = list(TIMED_COLUMNS) if self.at_days is None else [f"{n}_t{k}" for k in timed for n in TIMED_COLUMNS]
        names += [*INITIAL_COLUMNS, *RUN_COLUMNS]
        present = {name for row in self._rows.values() for name in row}
        return [name for name in names if name in present] + own_columns(self._rows, names)

    def member_routes(self):
        """{route: members} of the members with a row: "batch" (planned as a group and integrated together,
        :mod:`spinorbit.ensemble.batch`), "scene" (their own Scene run), "torque-free" (vectorised) or
        "self-run" (a member that runs itself)."""
        counts = {}
        for row in self._rows.values():
            route = row.get("ensemble_route", "scene")
            counts[route] = counts.get(route, 0) + 1
        return dict(sorted(counts.items()))

    def table(self):
        """One row per member in member order: parameters, outcome columns, ``error`` ("" when it ran).

        Members not run yet or failed have their outcome columns masked; ``meta`` holds the
        failures, the chunk size, the outcome times and the fingerprint.
        """
        table = self.parameters.copy()
        n = self.n_members
        for name in self.outcome_names():
            present = np.array([name in self._rows.get(i, {}) for i in range(n)])
            values = [self._rows[i][name] if p else None for i, p in zip(range(n), present)]
            base = name.rsplit("_t", 1)[0] if self.at_days is not None and "_t" in name else name
            if any(isinstance(v, str) for v in values):
                column = MaskedColumn([v if p else "" for v, p in zip(values, present)], mask=~present)
                table[name] = column if not present.all() else np.array(column.data)
            elif any(isinstance(v, bool) for v in values):
                column = MaskedColumn([bool(v) if p else False for v, p in zip(values, present)], mask=~present)
                table[name] = column if not present.all() else np.array(column.data)
            else:
                data = np.array([v if p else 0.0 for v, p in zip(values, present)], dtype=float)
                if base in OUTCOME_UNITS:
                    data = data * OUTCOME_UNITS[base]
                elif name in self.outcome_units:
                    data = data * self.outcome_units[name]
                table[name] = data if present.all() else Masked(data, mask=~present)
        errors = [f"{self._failures[i]['type']}: {self._failures[i]['message']}" if i in self._failures else ""
                  for i in range(n)]
        table["error"] = np.array(errors, dtype=str) if any(errors) else np.array([""] * n, dtype="<U1")
        table.meta.update({"members": n, "chunk_size": self.chunk_size, "fingerprint": self.fingerprint,
                           "failures": self.failures,
                           "outcome_times_tdb_days": None if self.at_days is None else self.at_days.tolist(),
                           "outcome_time": "last output time" if self.at_days is None else "named times (_t<k>)",
                           "route": self.route, "member_routes": self.member_routes()})
        return table
