"""Long runs of the core integrators, in chunks of simulated time, with checkpoints and resume.

:func:`integrate_resumable` runs one of the core integrators (DOP853 on (q, ω), DOP853 on the
canonical elements, or a symplectic splitting) from ``t0`` to the last output time as a sequence of
chunks of ``chunk`` time units. Each chunk is one ordinary call of the integrator from the state at
the chunk's start, ending exactly on the chunk boundary, so a chunk's result depends only on that
state (seven float64 numbers), the boundary times and the options — and every run, interrupted or
not, takes the same chunks. A checkpoint (:mod:`spinorbit.runs.checkpoint`) stores the boundary state
with its bits, the outputs so far and a fingerprint of the inputs; the resumed run therefore ends
with the same bits as the uninterrupted one (``tests/test_checkpoint_runs.py``).

Why restart the step-size controller at each boundary instead of saving it: the DOP853 kernels keep
the FSAL derivative and the proposed step inside one call; restarting both runs identically at every
boundary makes the result independent of where a run was interrupted, at the cost of the automatic
first step (2–3 short steps) once per chunk. With chunks of thousands of steps this is < 0.1 % of
the work; the chunked run is not bit-identical to one unchunked call (a different, equally valid
step sequence).
"""

from __future__ import annotations

import json
import math

import numpy as np

from spinorbit.runs.checkpoint import Checkpoint, CheckpointError, CheckpointSchedule, fingerprint
from spinorbit.core.dynamics.validation import validate_state
from spinorbit.core.integrators.elements import integrate_elements
from spinorbit.core.integrators.quaternion import default_atol, integrate_quaternion
from spinorbit.core.dynamics.validation import validate_output_times
from spinorbit.core.integrators.splitting import integrate_splitting

__all__ = ["METHODS", "RESUMABLE_KIND", "integrate_resumable"]

#: The integrators :func:`integrate_resumable` can drive, by name.
METHODS = {"dop853": integrate_quaternion, "elements": integrate_elements, "splitting": integrate_splitting}
#: ``kind`` of the checkpoints written by :func:`integrate_resumable`.
RESUMABLE_KIND = "core-integrator"


def _chunk_boundaries(t0: float, t_end: float, chunk: float) -> np.ndarray:
    """t0 + k·chunk (k = 1, 2, …) strictly before t_end, then t_end (in the run's direction)."""
    direction = 1.0 if t_end > t0 else -1.0
    count = math.ceil(abs(t_end - t0) / chunk)
    inner = t0 + direction * chunk * np.arange(1, count + 1)
    inner = inner[direction * (t_end - inner) > 0.0]
    return np.append(inner, t_end)


def integrate_resumable(method: str, y0, t0, t_out, model, chunk: float, schedule: CheckpointSchedule | None = None,
                        resume=None, **options):
    """Integrate in chunks of simulated time, writing checkpoints; resume bit for bit.

    Parameters
    ----------
    method : {"dop853", "elements", "splitting"}
        :func:`~spinorbit.core.integrators.quaternion.integrate_quaternion`,
        :func:`~spinorbit.core.integrators.elements.integrate_elements` or
        :func:`~spinorbit.core.integrators.splitting.integrate_splitting`.
    y0, t0, t_out, model
        As in :func:`~spinorbit.core.integrators.quaternion.integrate_quaternion`: state (q0..q3, ωx,
        ωy, ωz) with ω in rad per model time unit, start time, output times monotone away from t0.
    chunk : float
        Simulated time per chunk (model time unit, > 0). Checkpoints can only be written at chunk
        boundaries; choose a chunk that takes seconds of wall time, not milliseconds.
    schedule : spinorbit.runs.checkpoint.CheckpointSchedule, optional
        When and where to write checkpoints.
    resume : str or os.PathLike, optional
        A checkpoint of an interrupted call with the same arguments.
    **options
        Passed to the integrator (``rtol``, ``atol``, ``step``, ``scheme``, ...). For "dop853" the
        default ``atol`` is fixed once from ``y0`` (not re-derived per chunk).

    Returns
    -------
    ys : ndarray (n, 7)
        States at ``t_out``.

    Raises
    ------
    ValueError
        Unknown method, bad chunk, or what the integrator itself refuses.
    spinorbit.runs.checkpoint.CheckpointError
        ``resume`` is unreadable, corrupted, or from a run with other inputs.
    spinorbit.runs.checkpoint.RunStopped
        The schedule's ``stop_after_chunks`` was reached (after writing the checkpoint).
    """
    if method not in METHODS:
        raise ValueError(f"method: expected one of {sorted(METHODS)}, got {method!r}.")
    integrator = METHODS[method]
    y0 = validate_state(y0)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    given, chunk = chunk, float(chunk) if isinstance(chunk, (int, float, np.integer, np.floating)) else math.nan
    if not (math.isfinite(chunk) and chunk > 0.0):
        raise ValueError(f"chunk: expected a finite simulated time > 0 per chunk (model time unit), got {given!r}.")
    model = np.ascontiguousarray(model, dtype=float)
    if method == "dop853" and options.get("atol") is None:
        options["atol"] = default_atol(y0, options.get("rtol", 1e-10))
    options_text = json.dumps(options, sort_keys=True, default=lambda value: np.asarray(value).tolist())
    run_id = fingerprint(y0, np.array([t0, chunk]), t_out, model, np.frombuffer(
        f"{method}{options_text}".encode(), dtype=np.uint8))

    boundaries = _chunk_boundaries(t0, float(t_out[-1]), chunk)
    direction = 1.0 if t_out[-1] > t0 else -1.0
    ys = np.full((t_out.size, y0.size), np.nan)
    start, y, done = t0, y0, 0
    if resume is not None:
        checkpoint = Checkpoint.read(resume, kind=RESUMABLE_KIND)
        checkpoint.expect(resume, "inputs (fingerprint of y0, t0, t_out, model, method, options)",
                          checkpoint.setting(resume, "run", str), run_id)
        done = checkpoint.setting(resume, "chunks_done", int)
        if not 0 < done < boundaries.size:
            raise CheckpointError(f"checkpoint '{resume}': chunks_done = {done}, this run has chunks 1 to "
                                  f"{boundaries.size - 1}; the file was edited. Start the run again.")
        y = checkpoint.array(resume, "y", np.float64, (y0.size,))
        start = float(checkpoint.array(resume, "t", np.float64, (1,))[0])
        ys = checkpoint.array(resume, "ys", np.float64, ys.shape)
        if start != boundaries[done - 1] or not np.all(np.isfinite(y)):
            raise CheckpointError(f"checkpoint '{resume}': its state at t = {start!r} is not this run's state at "
                                  f"chunk {done} (t = {boundaries[done - 1]!r}); the file was edited. Start again.")
    for k in range(done, boundaries.size):
        end = boundaries[k]
        first = np.searchsorted(direction * t_out, direction * start, side="left" if k == 0 else "right")
        last = np.searchsorted(direction * t_out, direction * end, side="right")
        times = t_out[first:last]
        if times.size == 0 or times[-1] != end:
            times = np.append(times, end)
        chunk_ys = integrator(y, start, times, model, **options)
        ys[first:last] = chunk_ys[:last - first]
        start, y = end, chunk_ys[-1].copy()
        if schedule is not None and k + 1 < boundaries.size and schedule.due(k + 1):
            schedule.write(Checkpoint(
                kind=RESUMABLE_KIND,
                arrays={"y": y, "t": np.array([start]), "ys": ys},
                meta={"run": run_id, "chunks_done": k + 1, "method": method},
            ), k + 1)
    return ys
