"""A one-line notice on stderr while numba compiles spinorbit's kernels on a first run (a cold cache).

spinorbit's kernels are cached on disk (``cache=True``, :mod:`spinorbit.core.jit`), so only a first run
— a fresh install, a new numba, an emptied ``NUMBA_CACHE_DIR`` — compiles them, which takes tens of
seconds during which a command would otherwise print nothing. numba announces every real compilation
with a ``numba:compile`` event (its event API, :mod:`numba.core.event`); a load from the cache raises
none. So the notice is printed at the first such event and never on a warm run, at no cost to it.
Like the progress bars (:class:`spinorbit.commands._common.Progress`) it speaks only to a terminal:
pipes, logs and scripts that read stderr (one line for an error, ``tests/stress/test_bad_input.py``)
see nothing extra.
"""

from __future__ import annotations

import contextlib
import sys

#: What the notice says (one line).
NOTICE = ("spinorbit: compiling the numba kernels (first run with this cache; they are cached for the next runs, "
          "about 15-30 s on 2 cores for spinorbit moon, longer on a loaded machine) ...")


@contextlib.contextmanager
def compile_notice(stream=None):
    """Within the block, print :data:`NOTICE` once to ``stream`` (stderr) when numba starts a compilation.

    Nothing is installed, and nothing printed, when ``stream`` is not a terminal.
    """
    from numba.core import event

    stream = sys.stderr if stream is None else stream
    if not getattr(stream, "isatty", lambda: False)():
        yield None
        return

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
