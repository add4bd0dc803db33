"""The ensemble's own worker processes: they leave Ctrl-C to the parent, die with it, and stop at once.

A ``ProcessPoolExecutor`` alone gets three things wrong for a long ensemble (issue 36):

- Ctrl-C at a terminal reaches the whole process group, so every worker raises its own
  ``KeyboardInterrupt`` (tracebacks on stderr) while the parent is still deciding what to keep;
  here the workers ignore SIGINT and the parent stops them (:func:`stop_pool`).
- After SIGKILL of the parent its workers are re-parented to PID 1 and keep computing, holding the
  pipes open. Here each worker asks the kernel for SIGKILL when its parent dies
  (``prctl(PR_SET_PDEATHSIG)``, Linux; the only ``ctypes`` outside the REBOUND door, since Python
  has no binding for it), or elsewhere polls ``os.getppid()`` from a daemon thread. The kernel's
  signal also stops a worker inside a compiled kernel, which holds the GIL and so would block a
  polling thread until it returns.
- Leaving the pool's ``with`` block on an exception waits for every submitted chunk
  (``shutdown(wait=True)``). :func:`stop_pool` cancels the chunks not started and terminates the
  workers, so a stopped run ends within a second; the chunks already finished were checkpointed
  as they arrived.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os
import signal
import sys
import threading
import time

__all__ = ["PARENT_POLL_SECONDS", "process_pool", "stop_pool", "worker_initializer"]

#: How often a worker without ``prctl`` checks that its parent is alive (seconds).
PARENT_POLL_SECONDS = 0.5
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def _die_with_parent_linux() -> bool:
    import ctypes  # noqa: PLC0415 — Linux only; see the module docstring

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_parent(parent_pid) -> None:
    def watch():
        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="spinorbit-parent-watch", daemon=True).start()


def worker_initializer(parent_pid, parent_is_direct=True) -> None:
    """Run first in every worker: SIGINT ignored (the parent stops the pool), SIGTERM fatal, death with the parent.

    Parameters
    ----------
    parent_pid : int
        The process that made the pool.
    parent_is_direct : bool
        Whether the worker is its direct child (fork and spawn; a forkserver's workers are the
        server's children, and the server exits when the parent does).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # SIGTERM kills at once, whatever handler a forked worker inherited (the CLI's raises an exception,
    # which the pool's worker loop would catch and carry on): stop_pool relies on it.
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    watched = os.getppid()
    if not (sys.platform.startswith("linux") and _die_with_parent_linux()):
        _watch_parent(watched)
    if parent_is_direct and watched != parent_pid:  # the parent died before the kernel was asked
        os._exit(1)


def process_pool(workers) -> concurrent.futures.ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` of ``workers`` processes set up by :func:`worker_initializer`."""
    context = multiprocessing.get_context()
    direct = context.get_start_method() != "forkserver"
    return concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=context,
                                                  initializer=worker_initializer, initargs=(os.getpid(), direct))


def stop_pool(pool, timeout=1.0) -> None:
    """Cancel ``pool``'s chunks not started, terminate its workers and let it go without waiting for them.

    The order matters on Python < 3.14: the pool's manager thread cancels the chunks not started
    (``cancel_futures``) and forgets them before it sees the workers gone; a chunk cancelled by
    anyone else would make it fail while marking the pool broken (``InvalidStateError``), leaving
    the interpreter's exit to wait for it.
    """
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    # Before 3.14 the pool has no public call that stops a running worker; its table of processes
    # does (read before shutdown, which drops it).
    processes = [] if terminate is not None else list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    if terminate is not None:
        terminate()
        return
    for process in processes:
        if process.is_alive():
            process.terminate()
    deadline = time.monotonic() + timeout
    for process in processes:  # reaped now, so that the manager thread (and exit) need not wait for them
        process.join(max(0.0, deadline - time.monotonic()))
