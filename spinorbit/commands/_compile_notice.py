"""A one-line notice on stderr while numba compiles spinorbit's kernels on a first run (a cold cache).

spinorbit's kernels are cached on disk (``cache=True``, :mod:`spinorbit.core.jit`), so only a first run
— a fresh install, a new numba, an emptied ``NUMBA_CACHE_DIR`` — compiles them, which takes tens of
seconds during which a command would otherwise print nothing. numba announces every real compilation
with a ``numba:compile`` event (its event API, :mod:`numba.core.event`); a load from the cache raises
none. So the notice is printed at the first such event and never on a warm run, at no cost to it.

It goes to stderr whether or not stderr is a terminal: a run piped to a log (``spinorbit moon 2> log``,
a batch job) is the one that most needs to say why it is silent for ~25 s. Scripts that want stderr to hold
nothing but an error line set ``SPINORBIT_COMPILE_NOTICE=0`` (the test suite does, in
``tests/conftest.py``, so that a cold cache on CI cannot add a line to the errors it checks); an error,
when there is one, is always the last line.
"""

from __future__ import annotations

import contextlib
import os
import sys

#: What the notice says (one line).
NOTICE = ("spinorbit: compiling the numba kernels (first run with this cache; they are cached for the next runs, "
          "about 15-30 s on 2 cores for spinorbit moon, longer on a loaded machine) ...")

#: The environment variable that silences the notice when set to ``0`` (or ``no``, ``off``, ``false``).
SWITCH = "SPINORBIT_COMPILE_NOTICE"


def _silenced() -> bool:
    return os.environ.get(SWITCH, "").strip().lower() in {"0", "no", "off", "false"}


@contextlib.contextmanager
def compile_notice(stream=None):
    """Within the block, print :data:`NOTICE` once to ``stream`` (stderr) when numba starts a compilation.

    Nothing is installed, and nothing printed, when the environment variable :data:`SWITCH` is ``0``.
    """
    from numba.core import event

    if _silenced():
        yield None
        return
    stream = sys.stderr if stream is None else stream

    class Notice(event.Listener):
        said = False

        def on_start(self, _event):
            if not self.said:
                self.said = True
                print(NOTICE, file=stream, flush=True)

        def on_end(self, _event):
            pass

    listener = Notice()
    event.register("numba:compile", listener)
    try:
        yield listener
    finally:
        event.unregister("numba:compile", listener)
