"""What the Numba just-in-time compiler does, said out loud; and a warm-up for images and clusters.

The simulator's kernels are compiled by Numba on their first call in a fresh installation (tens
of seconds on a small machine) and cached on disk next to the package (or in
``NUMBA_CACHE_DIR``); later runs load them in a fraction of a second. :func:`compile_notice`
tells the user when that first compilation happens, so a first run does not look hung, and
:func:`pymoo_rail.warmup.warmup` compiles ahead of time (``pymoo-rail warmup``), e.g. when building a container
image or before a study on a cluster whose workers share the cache directory.
"""

from __future__ import annotations

import os
import sys
import time
from contextlib import contextmanager
from typing import Callable, Iterator

from numba import njit
from numba.core import event

PACKAGE = "pymoo_rail"

# Decorator of the kernels' small helpers (forces, one cell's step and accounting). LLVM inlines
# them into every caller (``forceinline``: the LLVM attribute ``alwaysinline``), so a cell costs
# what it cost with Numba's own inlining (``inline="always"``), which re-ran the untyped pipeline
# of a helper, and of every helper it inlines in turn, at each call site: 66 % of the first run's
# compile (``benchmarks/compile_profile.py``). No reference counting: they allocate nothing, and a
# called helper with it increfs the model's arrays on every call. They keep their Python wrapper
# (``no_cpython_wrapper`` would save a little compile, but a call from Python then crashes).
inlined = njit(cache=True, no_cfunc_wrapper=True, forceinline=True, _nrt=False)
"""``njit`` for a kernel helper: inlined by LLVM into every caller, no reference counting."""
called = njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
"""``njit`` for a helper off the hot path of a case without it (the efficiency-map lookup): compiled
once and called, not inlined at every call site (inlined, its two bisections cost 4.4 s of the
first run's compile, ``benchmarks/first_run.py``); no reference counting, as for :data:`inlined`."""
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
def compile_notice(say: Callable[[str], None] = _say_stderr, summary: bool = True,
                   message: str = NOTICE) -> Iterator[CompileWatch]:
    """Say when Numba starts compiling a package kernel inside the block (once), and how long it took.

    Parameters
    ----------
    say : callable
        Where the lines go (default: standard error; with a tqdm bar pass ``tqdm.write``).
    summary : bool
        At the end of the block, say how long the compilation took (only if there was one).
    message : str
        The line said when the first compilation starts (it must say that it is the first run only).

    Yields
    ------
    CompileWatch
        The listener, with ``n_compiled`` and ``compile_s``.
    """
    watch = CompileWatch(say, message)
    with event.install_listener("numba:compile", watch):
        yield watch
    if summary and watch.n_compiled:
        say(f"compiled {watch.n_compiled} simulator functions in {watch.compile_s:.0f} s (cached: later runs "
            "start at once)")


class CompileProfile(event.Listener):
    """Where Numba's compile time goes, per function and per stage (exclusive CPU time of the thread).

    Listens to ``numba:compile`` (one dispatcher compiling one signature) and ``numba:run_pass``
    (one compiler pass of one function). Time is charged to the innermost event open, so nested
    compilations (a callee compiled during its caller's type inference) are not counted twice.
    With ``llvm=True`` (:func:`compile_profile`) the LLVM stages of a code library are timed
    too: ``llvm:function passes``, ``llvm:module passes`` (the optimisation of the linked final
    module, where LLVM inlines) and ``llvm:machine code``; otherwise they fall inside the
    ``NativeLowering`` pass.

    Attributes
    ----------
    seconds : dict
        ``(module.qualname of the function, stage) -> seconds``.
    compiles : dict
        ``module.qualname -> number of signatures compiled``.
    signatures : dict
        ``module.qualname -> [argument types of each compilation]`` (to spot specialisations).
    """

    def __init__(self) -> None:
        self.seconds: dict[tuple[str, str], float] = {}
        self.compiles: dict[str, int] = {}
        self.signatures: dict[str, list[str]] = {}
        self._stack: list[list] = []  # [qualname, stage, started, child seconds]

    def _open(self, qualname: str, stage: str) -> None:
        # the compiling thread's CPU time: not inflated by other processes on a loaded machine
        self._stack.append([qualname, stage, time.thread_time(), 0.0])

    def _close(self) -> None:
        qualname, stage, started, children = self._stack.pop()
        spent = time.thread_time() - started
        key = (qualname, stage)
        self.seconds[key] = self.seconds.get(key, 0.0) + spent - children
        if self._stack:
            self._stack[-1][3] += spent

    def _owner(self) -> str:
        return self._stack[-1][0] if self._stack else "?"

    def on_start(self, ev: event.Event) -> None:
        """A compile or a compiler pass starts: open it (and count the signature of a compile)."""
        data = ev.data or {}
        if ev.kind == "numba:compile":
            dispatcher = data.get("dispatcher")
            func = getattr(dispatcher, "py_func", None)
            qualname = f"{getattr(func, '__module__', '?')}.{getattr(func, '__qualname__', '?')}"
            self.compiles[qualname] = self.compiles.get(qualname, 0) + 1
            self.signatures.setdefault(qualname, []).append(str(data.get("args", "")))
            self._open(qualname, "other")
        else:
            self._open(f"{data.get('module', '?')}.{data.get('qualname', '?')}", data.get("name", "?").split(" [")[0])

    def on_end(self, ev: event.Event) -> None:
        """The innermost open compile or pass ends: charge its exclusive time."""
        self._close()

    def table(self) -> list[tuple[str, float, dict[str, float]]]:
        """``(function, total s, {stage: s})`` per function, the most expensive first."""
        per: dict[str, dict[str, float]] = {}
        for (qualname, stage), s in self.seconds.items():
            per.setdefault(qualname, {})[stage] = per.setdefault(qualname, {}).get(stage, 0.0) + s
        rows = [(q, sum(st.values()), st) for q, st in per.items()]
        return sorted(rows, key=lambda row: -row[1])

    def summary(self, top: int = 25, signatures: bool = False) -> str:
        """The profile as text: compile CPU by module, by stage, and per function (the ``top`` dearest).

        Per function: total seconds, signatures compiled and the stages of at least 0.2 s. With
        ``signatures``, also every function compiled more than once and where its argument types
        differ (a specialisation that may be avoidable).
        """
        rows = self.table()
        stages: dict[str, float] = {}
        modules: dict[str, float] = {}
        for qualname, s, per in rows:
            module = qualname.split(".<locals>")[0].rsplit(".", 1)[0]
            modules[module] = modules.get(module, 0.0) + s
            for stage, t in per.items():
                stages[stage] = stages.get(stage, 0.0) + t
        lines = [f"compile (CPU) {sum(stages.values()):.1f} s", "", "by module:"]
        lines += [f"  {s:7.1f} s  {m}" for m, s in sorted(modules.items(), key=lambda kv: -kv[1])[:10]]
        lines += ["", "by stage:"] + [f"  {s:7.1f} s  {st}" for st, s in sorted(stages.items(), key=lambda kv: -kv[1])[:12]]
        lines += ["", f"by function (top {top}): total s, signatures, stages >= 0.2 s"]
        for qualname, s, per in rows[:top]:
            parts = ", ".join(f"{k} {v:.1f}" for k, v in sorted(per.items(), key=lambda kv: -kv[1]) if v >= 0.2)
            lines.append(f"  {s:7.1f}  x{self.compiles.get(qualname, 0)}  {qualname}: {parts}")
        if signatures:
            lines += ["", "functions compiled for more than one signature (the arguments where they differ):"]
            for qualname, sigs in self.signatures.items():
                if len(sigs) > 1:
                    start = max(0, len(os.path.commonprefix(sigs)) - 30)
                    lines.append(f"  {qualname}: " + " | ".join(sig[start:][:120] for sig in sigs))
        return "\n".join(lines)


@contextmanager
def compile_profile(llvm: bool = True) -> Iterator[CompileProfile]:
    """Profile every Numba compilation inside the block (see :class:`CompileProfile`).

    With ``llvm`` the LLVM stages of Numba's CPU code libraries are timed by wrapping three of
    their methods for the duration of the block (restored afterwards).
    """
    from numba.core import codegen

    profile = CompileProfile()
    wrapped = {"_optimize_functions": "llvm:function passes",
               "_optimize_final_module": "llvm:module passes",
               "_finalize_specific": "llvm:machine code"}
    originals = {}
    if llvm:
        for cls in (codegen.CPUCodeLibrary, codegen.JITCodeLibrary):
            for name, stage in wrapped.items():
                if name in vars(cls):
                    originals[(cls, name)] = vars(cls)[name]
                    setattr(cls, name, _timed(profile, vars(cls)[name], stage))
    try:
        with event.install_listener("numba:compile", profile), event.install_listener("numba:run_pass", profile):
            yield profile
    finally:
        for (cls, name), method in originals.items():
            setattr(cls, name, method)


def _timed(profile: CompileProfile, method: Callable, stage: str) -> Callable:
    def timed(self, *args, **kwargs):
        profile._open(profile._owner(), stage)
        try:
            return method(self, *args, **kwargs)
        finally:
            profile._close()
    return timed
