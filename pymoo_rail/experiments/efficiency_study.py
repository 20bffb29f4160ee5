"""ms-eetc's efficiency study beside pymoo-rail's exact solver: perfect, static and dynamic efficiency.

Kouzoupis et al. (Transportation Research Part C 2023, fig. 5): each solver plans the optimal run under
three efficiency models and each run is costed under the dynamic model (the case and the models are
:mod:`pymoo_rail.optimal.efficiency_study`'s). ms-eetc runs through :mod:`pymoo_rail.experiments.peers`'
driver; ``benchmarks/efficiency_study.py`` is the command line (``docs/efficiency.md``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.experiments.peers import mseetc_track, run_mseetc_json
from pymoo_rail.model.efficiency import maps_from_losses
from pymoo_rail.optimal import efficiency_study as es

TRACK_ID = "efficiency_study_8500"
COLOURS = {"perfect": "tab:blue", "static": "tab:red", "dynamic": "tab:green"}


def mseetc_run(checkout: Path, python: str, intervals: int, case, running_time_s: float, losses: str,
               loss_grid: dict | None = None) -> dict:
    """ms-eetc's optimal run under one loss model (``"perfect"``, ``"static"`` or ``"dynamic"``), N = ``intervals``."""
    study = {"losses": losses, "eta_static": es.STATIC_EFFICIENCY, "aux_w": es.AUX_POWER_KW * 1000.0,
             "eta_gear": es.GEAR_EFFICIENCY}
    if loss_grid is not None:
        study["loss_grid"] = loss_grid
    return run_mseetc_json(checkout, python, TRACK_ID, running_time_s, intervals,
                           {TRACK_ID: mseetc_track(case, TRACK_ID)}, case.initial_speed_ms, case.final_speed_ms,
                           1, study)


def sampled_models(checkout: Path, python: str, intervals: int, case) -> tuple[dict, int]:
    """The three models of pymoo-rail, the dynamic one's maps sampled from ms-eetc's loss function.

    Returns the models and the number of map nodes held at the efficiency floor (``maps_from_losses``).
    """
    speeds_kmh, forces_kn = es.loss_grid(160.0, case.train.traction.max_force_kn)
    forces_n = es.operating_forces_kn(case, speeds_kmh, forces_kn) * 1000.0
    grid = {"speeds_ms": (speeds_kmh / KMH_PER_MS).tolist(), "forces_n": np.hstack((forces_n, -forces_n)).tolist()}
    run = mseetc_run(checkout, python, intervals, case, es.STUDY_MIN_TIME_S * 1.2, "perfect", grid)
    loss_w = np.asarray(run["loss_w"])
    n = forces_kn.shape[0]
    traction, regen, held = maps_from_losses(speeds_kmh, forces_kn, loss_w[:, :n], loss_w[:, n:], es.AUX_POWER_KW)
    return es.efficiency_models(case, traction, regen), held


def reserve_rows(checkout: Path, python: str, intervals: int, case, models: dict,
                 reserve_pct: float) -> tuple[list[dict], list]:
    """Both solvers, three models, one time reserve (%): the table rows and the figure's runs."""
    running_time_s = es.STUDY_MIN_TIME_S * (1.0 + reserve_pct / 100.0)
    ours = es.planned_runs(models, running_time_s)
    rows, runs = [], []
    for row in ours:
        name, run = row["model"], row["run"]
        theirs = mseetc_run(checkout, python, intervals, case, running_time_s, name)
        replayed = es.profile_energy_kwh(models["dynamic"], theirs["position_m"], theirs["speed_ms"], theirs["time_s"])
        rows.append({"reserve_pct": reserve_pct, "model": name, "time_s": running_time_s,
                     "ours_run_s": row["running_time_s"], "ours_own_kwh": row["own_kwh"],
                     "mseetc_own_kwh": theirs["energy_kwh"],
                     "own_diff_pct": 100.0 * (row["own_kwh"] / theirs["energy_kwh"] - 1.0),
                     "ours_dynamic_kwh": row["dynamic_kwh"], "mseetc_dynamic_kwh": theirs["dynamic_energy_kwh"],
                     "dynamic_diff_pct": 100.0 * (row["dynamic_kwh"] / theirs["dynamic_energy_kwh"] - 1.0),
                     "mseetc_run_in_ours_kwh": replayed,
                     "ours_part_power_km": es.part_power_km(case, run.position_m, run.speed_ms),
                     "mseetc_part_power_km": es.part_power_km(case, theirs["position_m"], theirs["speed_ms"]),
                     "ours_cpu_s": row["cpu_s"], "mseetc_cpu_s": theirs["cpu_s"]})
        runs.append((f"pymoo-rail {name} ({row['dynamic_kwh']:.1f} kWh)", run.position_m, run.speed_ms,
                     COLOURS[name], "-"))
        runs.append((f"ms-eetc {name} ({theirs['dynamic_energy_kwh']:.1f} kWh)", theirs["position_m"],
                     theirs["speed_ms"], COLOURS[name], "--"))
        print({k: round(v, 4) if isinstance(v, float) else v for k, v in rows[-1].items()}, flush=True)
    return rows, runs


def findings(table: pd.DataFrame) -> dict[str, str]:
    """The differences in numbers, for the report's template: per model, and where the dynamic gap comes from.

    ``own_within``: the largest |own_diff_pct| of the fixed models; ``dynamic_range``: their
    dynamic_diff_pct range; ``faithful_range``: ms-eetc's run costed by pymoo-rail's maps over ms-eetc's
    figure; ``control_range``: pymoo-rail's optimum over ms-eetc's run under the same maps;
    ``dynamic_own_range``: pymoo-rail's dynamic optimum over ms-eetc's figure (all in %);
    ``part_power``: both solvers' part-power distances per reserve (km, pymoo-rail / ms-eetc).
    """
    dyn = table[table["model"] == "dynamic"]
    fixed = table[table["model"] != "dynamic"]
    faithful = 100.0 * (dyn["mseetc_run_in_ours_kwh"] / dyn["mseetc_dynamic_kwh"] - 1.0)
    control = 100.0 * (dyn["ours_dynamic_kwh"] / dyn["mseetc_run_in_ours_kwh"] - 1.0)
    part = ", ".join(f"{r['ours_part_power_km']:.1f} / {r['mseetc_part_power_km']:.1f} km at {r['reserve_pct']:g} %"
                     for _, r in dyn.iterrows()) if "ours_part_power_km" in dyn else ""
    return {"own_within": f"{fixed['own_diff_pct'].abs().max():.2f}",
            "dynamic_range": f"{fixed['dynamic_diff_pct'].min():+.2f} to {fixed['dynamic_diff_pct'].max():+.2f}",
            "faithful_range": f"{faithful.min():+.2f} to {faithful.max():+.2f}",
            "control_range": f"{control.min():+.2f} to {control.max():+.2f}",
            "dynamic_own_range": f"{dyn['own_diff_pct'].min():+.2f} to {dyn['own_diff_pct'].max():+.2f}",
            "part_power": part}
