"""How the study runner and case loading scale on this machine: one study on several backends,
and a case's load and grid build against its number of gradient rows.

``benchmarks/studies.py`` and ``benchmarks/case_loading.py`` print these measurements.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import replace
from pathlib import Path
from typing import Mapping

import numpy as np
import pandas as pd

from pymoo_rail.cases import load_case, write_case
from pymoo_rail.experiments.results import load_results
from pymoo_rail.experiments.runner import run_study
from pymoo_rail.model import build_grid


def backend_timings(study, backends: Mapping[str, Mapping]) -> tuple[pd.DataFrame, float]:
    """Run ``study`` once per backend (``name -> run_study keyword arguments``), each into a fresh folder.

    Returns
    -------
    (pandas.DataFrame, float)
        Per backend ``backend``, ``wall_s``, ``speed_up`` over the first backend and ``identical``
        (every front equal bit for bit to the first backend's); and the summed wall time of the
        runs themselves in the first backend (what the backends share out).
    """
    times, frames = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, kwargs in backends.items():
            directory = Path(tmp) / name.replace(" ", "_")
            start = time.perf_counter()
            run_study(study, directory, progress=False, **kwargs)
            times[name] = time.perf_counter() - start
            frames[name] = load_results(directory)
    first = next(iter(backends))
    reference = frames[first]
    table = pd.DataFrame([{"backend": name, "wall_s": seconds, "speed_up": times[first] / seconds,
                           "identical": all(np.array_equal(a, b) for a, b in zip(reference["F"], frames[name]["F"]))}
                          for name, seconds in times.items()])
    return table, float(reference["wall_time_s"].sum())


def case_with_rows(n_rows: int, name: str = "yizhuang"):
    """The built-in case ``name`` with ``n_rows`` gradient rows of -30 to +30 permille (seeded by ``n_rows``)."""
    case = load_case(name)
    edges = np.linspace(0.0, case.line.length_m, n_rows + 1)
    permille = np.round(np.random.default_rng(n_rows).uniform(-30.0, 30.0, n_rows), 3)
    rows = tuple(zip(edges[:-1].tolist(), edges[1:].tolist(), permille.tolist()))
    return replace(case, name=f"{name}-{n_rows}-rows", line=replace(case.line, gradients=rows))


def load_and_grid_timing(case, folder: str | Path) -> dict:
    """Write ``case`` into ``folder``, then time ``load_case`` and ``build_grid`` on the file (wall and CPU s).

    Returns
    -------
    dict
        ``file_mb``, ``load_s``, ``load_cpu_s``, ``grid_s``, ``grid_cpu_s``; the file is removed.
    """
    path = write_case(case, Path(folder) / f"{case.name}.toml")
    start, start_cpu = time.perf_counter(), time.process_time()
    loaded_case = load_case(path)
    loaded, loaded_cpu = time.perf_counter(), time.process_time()
    build_grid(loaded_case)
    gridded, gridded_cpu = time.perf_counter(), time.process_time()
    row = {"file_mb": path.stat().st_size / 1e6, "load_s": loaded - start, "load_cpu_s": loaded_cpu - start_cpu,
           "grid_s": gridded - loaded, "grid_cpu_s": gridded_cpu - loaded_cpu}
    path.unlink()
    return row
