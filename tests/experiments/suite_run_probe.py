"""Run suite family runs in this (fresh) interpreter and print, as JSON, which package files each executed.

Used by ``test_suite_fingerprint.py`` as ``python suite_run_probe.py '<runs as JSON>'``, where each
run is ``[family, algorithm, {algorithm parameters}]`` (n_var 10, instance seed 1, 40 evaluations).
A file counts as executed by a run when a function defined in it is called while the run computes
(``execute_run``, from its fingerprint to its record); code run while a module is being imported
(its body, class bodies, decorators) is not a call on the run's path. The output also lists the
package's modules in ``sys.modules`` at the end, so the test can check those that were only imported.
"""

from __future__ import annotations

import json
import sys
import threading
from pathlib import Path

import pymoo_rail
from pymoo_rail.experiments.runner import execute_run
from pymoo_rail.experiments.spec import Budget, RunSpec, algorithm, problem

ROOT = str(Path(pymoo_rail.__file__).resolve().parent) + "/"


def _importing(frame) -> bool:
    """True when ``frame`` runs inside a module body being imported (below this script's own frames)."""
    while frame is not None and frame.f_globals.get("__name__") != "__main__":
        if frame.f_code.co_name == "<module>":
            return True
        frame = frame.f_back
    return False


def executed_files(run: RunSpec) -> list[str]:
    """The package files (relative paths) whose functions ``execute_run(run)`` calls."""
    files: set[str] = set()

    def profile(frame, event, arg):
        path = frame.f_code.co_filename
        if event == "call" and path.startswith(ROOT) and not _importing(frame):
            files.add(path[len(ROOT):])

    sys.setprofile(profile)
    threading.setprofile(profile)
    try:
        execute_run(run)
    finally:
        sys.setprofile(None)
        threading.setprofile(None)
    return sorted(files)


def main(runs_json: str) -> None:
    runs = [RunSpec(problem("suite_family", family=family, n_var=10, seed=1), algorithm(name, **params), 1,
                    Budget("n_eval", 40)) for family, name, params in json.loads(runs_json)]
    executed = [executed_files(run) for run in runs]
    modules = sorted(str(Path(m.__file__).resolve())[len(ROOT):] for name, m in list(sys.modules.items())
                     if name.split(".")[0] == "pymoo_rail" and getattr(m, "__file__", None))
    print(json.dumps({"executed": executed, "modules": modules}))


if __name__ == "__main__":
    main(sys.argv[1])
