"""What the Numba just-in-time compiler does, said out loud; and a warm-up for images and clusters.

The simulator's kernels are compiled by Numba on their first call in a fresh installation (tens
of seconds on a small machine) and cached on disk next to the package (or in
``NUMBA_CACHE_DIR``); later runs load them in a fraction of a second. :func:`compile_notice`
tells the user when that first compilation happens, so a first run does not look hung, and
:func:`pymoo_rail.warmup.warmup` compiles ahead of time (``pymoo-rail warmup``), e.g. when building a container
image or before a study on a cluster whose workers share the cache directory.
"""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from typing import Callable, Iterator

from numba.core import event

PACKAGE = "pymoo_rail"
NOTICE = ("compiling the simulator (first run only: Numba compiles the kernels once and caches them "
          "on disk; this takes a while on a small machine) ...")


def _say_stderr(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


class CompileWatch(event.Listener):
    """Numba compile-event listener: announces the first compilation of a package kernel.

    Attributes
    ----------
    n_compiled : int
        Package functions compiled so far (outermost compilations only).
    compile_s : float
        Wall time spent in those compilations (s).
    """

    def __init__(self, say: Callable[[str], None] = _say_stderr, message: str = NOTICE):
        self.say = say
        self.message = message
        self.n_compiled = 0
        self.compile_s = 0.0
        self._depth = 0
        self._started = 0.0

    @staticmethod
    def _ours(ev: event.Event) -> bool:
        dispatcher = (ev.data or {}).get("dispatcher")
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        return module.startswith(PACKAGE)

    def on_start(self, ev: event.Event) -> None:
        """Numba's compile-start event: announce the first compile and start the clock at the outermost one."""
        if not self._ours(ev):
            return
        if self._depth == 0:
            if self.n_compiled == 0:
                self.say(self.message)
            self._started = time.perf_counter()
        self._depth += 1

    def on_end(self, ev: event.Event) -> None:
        """Numba's compile-end event: count the outermost compile of our kernels and its time."""
        if not self._ours(ev) or self._depth == 0:
            return
        self._depth -= 1
        if self._depth == 0:
            self.n_compiled += 1
            self.compile_s += time.perf_counter() - self._started


@contextmanager
def compile_notice(say: Callable[[str], None] = _say_stderr, summary: bool = True) -> Iterator[CompileWatch]:
    """Say when Numba starts compiling a package kernel inside the block (once), and how long it took.

    Parameters
    ----------
    say : callable
        Where the lines go (default: standard error; with a tqdm bar pass ``tqdm.write``).
    summary : bool
        At the end of the block, say how long the compilation took (only if there was one).

    Yields
    ------
    CompileWatch
        The listener, with ``n_compiled`` and ``compile_s``.
    """
    watch = CompileWatch(say)
    with event.install_listener("numba:compile", watch):
        yield watch
    if summary and watch.n_compiled:
        say(f"compiled {watch.n_compiled} simulator functions in {watch.compile_s:.0f} s (cached: later runs "
            "start at once)")
