"""Solvers side by side: pymoo-rail's exact solver beside ms-eetc (and GPOPS-II's published figure).

ms-eetc (Kouzoupis et al., direct multiple shooting with CasADi/IPOPT) is not a dependency and not
on the package index: :func:`run_mseetc_json` runs it in a given checkout with a given interpreter
(its dependency casadi installed there), through a driver set up as for its fig. 10; answers on
generated lines are kept in CSV caches (:func:`mseetc_cached`) so that a slow N can be filled in the
background and read later. :func:`speed_ratios` and :func:`generated_summary` put both side by side.
``benchmarks/peers.py`` is the command line of this module (``docs/optimal.md``).
"""

from __future__ import annotations

import cProfile
import json
import math
import os
import pstats
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH

GPOPS_II = {"intercity-var-limit-100": (440.14, 7.0)}  # published (ms-eetc paper, fig. 10): kWh, s
# ms-eetc measured on this machine (2 cores, load average 1.1-1.2) on 2026-11-24, casadi 3.8.2, in the
# same run as pymoo-rail's committed figures: IPOPT process time of one solve (the best of 3);
# ms-eetc's own "CPU time" is IPOPT's wall time.
MSEETC_RECORDED = {
    ("intercity-var-limit-100", 100): (448.6395, 0.89), ("intercity-var-limit-100", 300): (441.0839, 3.44),
    ("intercity-var-limit-100", 1000): (440.3766, 12.31),
    ("intercity-level-10km", 100): (88.5501, 0.64), ("intercity-level-10km", 300): (88.3277, 2.69),
    ("intercity-level-10km", 1000): (88.2526, 11.20),
}
MSEETC_DATE = "2026-11-24"

# ms-eetc set up as for its fig. 10 (the GPOPS-II comparison); runs inside the checkout. ms-eetc was
# written for pandas < 2: its fillna(method=...) calls are served by ffill()/bfill() here.
MSEETC_DRIVER = """
import json, os, sys, time
from pathlib import Path
import pandas as pd
for cls in (pd.DataFrame, pd.Series):
    def fillna(self, value=None, *args, method=None, _f=cls.fillna, **kw):
        if method in ('ffill', 'pad'):
            return self.ffill()
        if method in ('bfill', 'backfill'):
            return self.bfill()
        return _f(self, value, *args, **kw)
    cls.fillna = fillna
sys.path.insert(0, os.getcwd())
from mseetc.train import Train
from mseetc.track import Track
from mseetc.ocp import casadiSolver
track_id, trip, n_int, tracks = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
v0, v_end, repeats = float(sys.argv[5]), float(sys.argv[6]), int(sys.argv[7])
train = Train(config={'id': 'NL_Intercity_VIRM6'})
train.forceMinPn = 0
train.forceMin = -train.forceMax
train.powerMax = 3129277
train.powerMin = -train.powerMax
train.etaTraction = 0.73
train.etaRgBrake = 0.73
# the efficiency study (optional 8th argument, JSON): the loss models of ms-eetc's fig. 5 script
study = json.loads(sys.argv[8]) if len(sys.argv) > 8 else None
result = {}
if study is not None:
    from mseetc.efficiency import totalLossesFunction
    from mseetc.utils import postProcessDataFrame
    # as in simulations/figure5.py: built first (it sets the train's power caps to its loss data's)
    dynamic = totalLossesFunction(train, auxiliaries=study['aux_w'], etaGear=study['eta_gear'])
    eta = study['eta_static']
    static = lambda f, v: f*v*(f > 0)*(1 - eta)/eta - (1 - eta)*f*v*(f < 0)
    train.powerLosses = {'perfect': lambda f, v: 0, 'static': static, 'dynamic': dynamic}[study['losses']]
    grid = study.get('loss_grid')
    if grid:  # the dynamic losses (W) at each speed (m/s) and its forces (N), for the other solver's maps
        result['loss_w'] = [[float(dynamic(f, v)) for f in forces] for v, forces in zip(grid['speeds_ms'],
                                                                                         grid['forces_n'])]
track = Track(config={'id': track_id}, pathJSON=Path(tracks))
opts = json.load(open('simulations/config.json'))
opts['minimumVelocity'] = 1
opts['numIntervals'] = n_int
solver = casadiSolver(train, track, opts)
best = None
for _ in range(repeats):
    t0 = time.process_time()
    df, stats = solver.solve(trip, terminalVelocity=v_end, initialVelocity=v0)
    cpu = time.process_time() - t0
    best = cpu if best is None else min(best, cpu)
result.update({'energy_kwh': float(df['Energy [kWh]'].sum()), 'cpu_s': best,
               'final_speed_ms': float(df['Velocity [m/s]'].iloc[-1])})
if study is not None:  # the run's energy under the dynamic losses, integrated as fig. 5 does, and the run
    train.powerLosses = dynamic
    real = postProcessDataFrame(df, solver.points, train, integrateLosses=True)
    result.update({'dynamic_energy_kwh': float(real['Energy [kWh]'].sum()),
                   'dynamic_losses_kwh': float(real['Losses [kWh]'].sum()),
                   'position_m': df['Position [m]'].tolist(), 'speed_ms': df['Velocity [m/s]'].tolist(),
                   'time_s': [float(t) for t in df.index]})
print(json.dumps(result))
"""


def run_mseetc(checkout: Path, python: str, track_id: str, trip_s: float, n_intervals: int,
               extra_tracks: dict | None = None, v0_ms: float = 1.0, v_end_ms: float = 1.0,
               repeats: int = 3) -> tuple[float, float]:
    """(energy kWh, CPU s) of ms-eetc on one case, run in its checkout (the best CPU of ``repeats`` solves).

    ``extra_tracks``: TTOBench track files (id -> JSON dict) to add beside the checkout's own.
    """
    energy, cpu, _ = run_mseetc_full(checkout, python, track_id, trip_s, n_intervals, extra_tracks, v0_ms,
                                     v_end_ms, repeats)
    return energy, cpu


def run_mseetc_full(checkout: Path, python: str, track_id: str, trip_s: float, n_intervals: int,
                    extra_tracks: dict | None = None, v0_ms: float = 1.0, v_end_ms: float = 1.0,
                    repeats: int = 3) -> tuple[float, float, float]:
    """:func:`run_mseetc` and ms-eetc's final speed (m/s)."""
    result = run_mseetc_json(checkout, python, track_id, trip_s, n_intervals, extra_tracks, v0_ms, v_end_ms, repeats)
    return result["energy_kwh"], result["cpu_s"], float(result.get("final_speed_ms", math.nan))


def run_mseetc_json(checkout: Path, python: str, track_id: str, trip_s: float, n_intervals: int,
                    extra_tracks: dict | None = None, v0_ms: float = 1.0, v_end_ms: float = 1.0,
                    repeats: int = 3, study: dict | None = None) -> dict:
    """Everything the driver prints for one case (its last line, checked by :func:`parse_mseetc_output`).

    ``study`` (the efficiency study, ``benchmarks/efficiency_study.py``): ``losses`` (``"perfect"``,
    ``"static"`` or ``"dynamic"``, the models of ms-eetc's fig. 5), ``eta_static``, ``aux_w``,
    ``eta_gear`` and optionally ``loss_grid`` (``speeds_ms`` and ``forces_n``, one list of forces per
    speed); the result then also holds
    the run (``position_m``, ``speed_ms``, ``time_s``), its energy under the dynamic losses and ``loss_w``.
    """
    with tempfile.TemporaryDirectory() as tmp:
        tracks = Path(tmp)
        for p in (checkout / "tracks").glob("*.json"):
            (tracks / p.name).write_text(p.read_text())
        level = json.loads((checkout / "tracks" / "00_var_speed_limit_100.json").read_text())
        level["metadata"]["id"] = "level_10km"
        level["stops"]["values"] = [0.0, 10000.0]
        level["speed limits"]["values"] = [[0.0, 140]]
        (tracks / "level_10km.json").write_text(json.dumps(level))
        for name, data in (extra_tracks or {}).items():
            (tracks / f"{name}.json").write_text(json.dumps(data))
        driver = tracks / "driver.py"
        driver.write_text(MSEETC_DRIVER)
        extra = [json.dumps(study)] if study is not None else []
        out = subprocess.run([python, str(driver), track_id, str(trip_s), str(n_intervals), str(tracks), str(v0_ms),
                              str(v_end_ms), str(repeats), *extra], cwd=checkout, capture_output=True, text=True,
                             check=True)
    parse_mseetc_output(out.stdout)
    return json.loads(out.stdout.strip().splitlines()[-1])


def parse_mseetc_output(stdout: str) -> tuple[float, float]:
    """(energy kWh, CPU s) from the driver's output: its last line is JSON (IPOPT prints above it)."""
    lines = [line for line in stdout.strip().splitlines() if line.strip()]
    if not lines:
        raise ValueError("ms-eetc printed nothing: expected a last line of JSON with energy_kwh and cpu_s")
    try:
        result = json.loads(lines[-1])
        energy, cpu = float(result["energy_kwh"]), float(result["cpu_s"])
    except (json.JSONDecodeError, KeyError, TypeError) as err:
        raise ValueError(f"ms-eetc's last line {lines[-1]!r} is not JSON with energy_kwh and cpu_s") from err
    if not (math.isfinite(energy) and cpu > 0.0):  # net energy < 0 on a line that descends enough
        raise ValueError(f"ms-eetc's last line {lines[-1]!r}: energy_kwh must be finite and cpu_s > 0")
    return energy, cpu


def pymoo_rail_row(name: str, running_time_s: float) -> dict:
    """pymoo-rail's exact solver on one case: energy (also moved to the requested time along lambda),
    certificate, CPU time (tables, search, replay and certificate) and the closed form where it applies.
    """
    from pymoo_rail.cases import load_case
    from pymoo_rail.optimal import OptimalSolver

    case = load_case(name)
    start = time.process_time()
    solver = OptimalSolver(case)
    tr = solver.profile(running_time_s)
    cpu = time.process_time() - start
    lam = tr.summary["lambda_w"]
    at_request = tr.energy.net_kwh + lam * (tr.running_time_s - running_time_s) / J_PER_KWH
    row = {"case": case.name, "requested_s": running_time_s, "run_s": tr.running_time_s,
           "energy_kwh": tr.energy.net_kwh, "at_request_kwh": at_request,
           "bound_kwh": tr.summary["energy_bound_kwh"], "cpu_s": cpu, "dp_solves": solver.n_solves}
    try:
        from pymoo_rail.optimal.flat import flat_track_optimum

        row["closed_form_kwh"] = flat_track_optimum(case, running_time_s).energy_kwh
    except ValueError:
        row["closed_form_kwh"] = float("nan")
    return row


def cpu_breakdown(name: str, running_time_s: float) -> dict:
    """CPU seconds of one profile (as timed by :func:`pymoo_rail_row`) per kernel of the exact solver.

    cProfile in ``time.process_time``: tables (``_count_targets`` + ``_fill_transitions``, default and
    the certificate's check grid), backward sweeps, forward runs and the rest (search, replay, certificate bookkeeping).
    """
    from pymoo_rail.cases import load_case
    from pymoo_rail.optimal import OptimalSolver

    case = load_case(name)
    profiler = cProfile.Profile(time.process_time)
    profiler.enable()
    OptimalSolver(case).profile(running_time_s)
    profiler.disable()
    stats = pstats.Stats(profiler).stats  # (file, line, function) -> (calls, ..., own time, cumulative time, ...)
    own = {name: [0, 0.0] for name in ("_count_targets", "_fill_transitions", "backward_sweep", "forward_rollout")}
    for (path, _, function), (_, calls, tottime, _, _) in stats.items():
        if path.endswith("dp.py") and function in own:
            own[function][0] += calls
            own[function][1] += tottime
    total = sum(v[2] for v in stats.values())
    tables = own["_count_targets"][1] + own["_fill_transitions"][1]
    sweeps, runs = own["backward_sweep"], own["forward_rollout"]
    return {"case": case.name, "cpu_s": total, "tables_s": tables, "sweeps": sweeps[0], "sweeps_s": sweeps[1],
            "forward_runs": runs[0], "forward_runs_s": runs[1], "rest_s": total - tables - sweeps[1] - runs[1]}


def best_cpu_s(call, repeats: int) -> float:
    """The least CPU time (``time.process_time``) of ``repeats`` calls of ``call()`` (s)."""
    times = []
    for _ in range(repeats):
        start = time.process_time()
        call()
        times.append(time.process_time() - start)
    return min(times)


def sweep_cpu(seed: int, factor: float, repeats: int = 5) -> list[str]:
    """CPU time of one backward sweep and one forward run of the exact solver, as report lines.

    On ``comparable_case(seed)`` at the price of time of its optimum at ``factor`` x the minimum running
    time, each the best of ``repeats``: with the singular speeds and the coast curves as states (what
    ``OptimalSolver`` solves; the curves' controls tabulated beforehand, ``dp.curve_controls``, as the
    solver keeps them across prices), with the singular speeds alone, and with the speed grid alone
    (``OptimalSolver(singular=False)``), alternated twice.
    """
    from pymoo_rail.optimal import OptimalSolver, dp, min_running_time

    case = comparable_case(seed)
    solver = OptimalSolver(case, certify=False)
    lambda_w = solver.profile(factor * min_running_time(case)).summary["lambda_w"]
    model, tables, n_speeds, bias = solver.simulator.model, solver.transition_tables(), solver.n_speeds, solver.top_bias
    n = model.position_m.shape[0]
    prices, floor_k = np.full(n - 1, lambda_w), np.zeros(n, dtype=np.int64)
    value = np.empty((n, n_speeds))
    terminal_j = dp.terminal_cost(model, n_speeds, bias, solver.end_speed_ms[0])
    curve_v, curve_p = dp.coast_curves(model, float(solver.end_speed_ms[0]), n_speeds, bias)
    lines = [f"{case.name}: {n - 1} cells, {tables[0].shape[0]} kinds of cell, {n_speeds} speed nodes, "
             f"{curve_v.shape[1]} coast curves, lambda {lambda_w:.0f} W (load average {os.getloadavg()[0]:.1f})"]
    for states in ("singular speeds and coast curves", "singular speeds", "speed grid alone") * 2:
        n_curves = curve_v.shape[1] if states.endswith("curves") else 0
        sing_v, sing_p, sing_val = (np.empty((n, dp.N_SINGULAR + n_curves)) for _ in range(3))
        if states == "speed grid alone":
            sing_v[:], sing_p[:] = 0.0, -1.0
        else:
            dp.singular_speeds(model, prices + model.aux_power_w, n_speeds, bias, sing_v, sing_p)
            sing_v[:, dp.N_SINGULAR:], sing_p[:, dp.N_SINGULAR:] = curve_v[:, :n_curves], curve_p[:, :n_curves]
        curves = dp.curve_controls(model, sing_v[:, dp.N_SINGULAR:], sing_p[:, dp.N_SINGULAR:], n_speeds,
                                   solver.max_targets, bias)
        sweep_s = best_cpu_s(lambda: dp.backward_sweep(model, prices, *tables, value, floor_k, terminal_j, sing_v,
                                                       sing_p, sing_val, solver.max_targets, bias, curves), repeats)
        run_s = best_cpu_s(lambda: dp.forward_run(model, prices + model.aux_power_w, value, solver.max_targets, bias,
                                                  solver.tie_j, sing_v, sing_p, sing_val), repeats)
        lines.append(f"{states}: backward sweep {sweep_s * 1e3:.1f} ms, forward run {run_s * 1e3:.1f} ms")
    return lines


def speed_ratios(ours: pd.DataFrame, theirs: pd.DataFrame) -> pd.DataFrame:
    """Per peer row: its CPU time over pymoo-rail's on the same case, and the energy difference (%)."""
    if len(theirs) == 0:
        return pd.DataFrame()
    merged = theirs.merge(ours[["case", "at_request_kwh", "cpu_s"]], on="case", suffixes=("", "_pymoo_rail"))
    # a published CPU time comes from another machine: no ratio
    merged["cpu_ratio"] = (merged["cpu_s"] / merged["cpu_s_pymoo_rail"]).where(merged["source"] != "published")
    merged["energy_diff_pct"] = 100.0 * (merged["at_request_kwh"] / merged["energy_kwh"] - 1.0)
    return merged[["case", "solver", "source", "cpu_ratio", "energy_diff_pct"]]


GENERATED_FACTORS = (1.05, 1.2, 1.5)  # running times of the generated lines, x the minimum running time
MSEETC_MIN_SPEED_MS = 1.0  # ms-eetc's smallest speed (its "minimumVelocity", as in the fig. 10 set-up)
MSEETC_MAX_DECEL_MS2 = 0.66  # VIRM6's deceleration cap in ms-eetc's train file


def comparable_case(seed: int):
    """``generate_case(seed, "intercity")`` as both solvers model it.

    The features ms-eetc cannot model are left out for both (curves, tunnels, neutral sections),
    boundary speeds are at least ms-eetc's 1 m/s, and the train has VIRM6's 0.66 m/s^2 deceleration
    cap of ms-eetc's train file; the rest (391 t, Davis, 213.9 kN / 3129 kW both ways, 0.73 both
    ways, all braking regenerative, point mass) is the same in both.
    """
    from dataclasses import replace

    from pymoo_rail.cases import generate_case

    case = generate_case(seed, "intercity")
    line = replace(case.line, curves=(), tunnels=(), neutral_sections=())
    return replace(case, line=line, train=replace(case.train, max_decel_ms2=MSEETC_MAX_DECEL_MS2),
                   initial_speed_ms=max(case.initial_speed_ms, MSEETC_MIN_SPEED_MS),
                   final_speed_ms=max(case.final_speed_ms, MSEETC_MIN_SPEED_MS))


def mseetc_track(case, track_id: str) -> dict:
    """The case's line as a TTOBench track file (stops, speed limits, gradients) for ms-eetc."""
    return {"metadata": {"id": track_id, "library version": "TTOBench v1.1"}, "altitude": {"unit": "m", "value": 0},
            "stops": {"unit": "m", "values": [0.0, case.line.length_m]},
            "speed limits": {"units": {"position": "m", "velocity": "km/h"},
                             "values": [[a, v] for a, _, v in case.line.speed_limits]},
            "gradients": {"units": {"position": "m", "slope": "permil"},
                          "values": [[a, g] for a, _, g in case.line.gradients]}}


CACHE_KEY = ("seed", "n", "time_s", "v0_ms", "v_end_ms")


def mseetc_cached(caches: list[Path], seed: int, case, t: float, n: int, checkout: Path | None, python: str,
                  repeats: int) -> tuple[float, float, float]:
    """(energy kWh, CPU s, end speed m/s) of ms-eetc at N = ``n``, read from the CSVs ``caches`` or run and appended
    to the first (NaN when it is in none and ``checkout`` is None, or ms-eetc fails).

    The key is the seed, N, the running time (to 1 ms) and the boundary speeds, so a rerun resumes where an
    interrupted one stopped, and a change of the minimum running time (the simulator's) reruns.
    """
    key = (seed, n, round(t, 3), round(case.initial_speed_ms, 6), round(case.final_speed_ms, 6))
    for cache in (c for c in caches if c.exists()):
        table = pd.read_csv(cache)
        hit = table[np.all([table[c].to_numpy() == k for c, k in zip(CACHE_KEY, key)], axis=0)]
        if len(hit):
            r = hit.iloc[-1]
            return float(r.energy_kwh), float(r.cpu_s), float(r.end_ms)
    if checkout is None:
        return math.nan, math.nan, math.nan
    try:
        result = run_mseetc_full(checkout, python, f"generated_{seed}", t, n,
                                 {f"generated_{seed}": mseetc_track(case, f"generated_{seed}")},
                                 case.initial_speed_ms, case.final_speed_ms, repeats)
    except subprocess.CalledProcessError:
        result = (math.nan, math.nan, math.nan)
    if caches:
        row = pd.DataFrame([dict(zip(CACHE_KEY, key)) | dict(zip(("energy_kwh", "cpu_s", "end_ms"), result))
                            | {"load": os.getloadavg()[0]}])
        row.to_csv(caches[0], mode="a", header=not caches[0].exists(), index=False)
    return result


def mseetc_only(seeds, checkout: Path, python: str, intervals: tuple[int, ...], cache: Path) -> None:
    """Fill ``cache`` with ms-eetc's answers on the generated lines, without solving them here."""
    from pymoo_rail.optimal import min_running_time

    for seed in seeds:
        case = comparable_case(seed)
        t_min = min_running_time(case)
        for factor in GENERATED_FACTORS:
            for n in intervals:
                start = time.time()
                energy, cpu, v_end = mseetc_cached([cache], seed, case, factor * t_min, n, checkout, python, 1)
                print(f"seed {seed} x{factor} N={n}: {energy:.4f} kWh, {cpu:.1f} s CPU, end {v_end:.3f} m/s"
                      f" ({time.time() - start:.0f} s wall)", flush=True)


def generated_rows(seeds, checkout: Path | None, python: str, intervals: tuple[int, ...], repeats: int,
                   cache: dict[int, list[Path]] | None = None) -> pd.DataFrame:
    """pymoo-rail and ms-eetc on generated lines at 1.05, 1.2 and 1.5 x the minimum running time.

    ``cache``: N -> the CSVs of ms-eetc's answers at that N, read only (:func:`mseetc_cached`; NaN where
    missing); the other N run here.
    """
    cache = cache or {}
    from pymoo_rail.optimal import OptimalSolver, min_running_time

    rows = []
    for seed in seeds:
        case = comparable_case(seed)
        t_min = min_running_time(case)
        features = case.description.split(": ", 1)[1]
        for factor in GENERATED_FACTORS:
            t = factor * t_min
            start = time.process_time()
            tr = OptimalSolver(case).profile(t)
            cpu = time.process_time() - start
            lam = tr.summary["lambda_w"]
            row = {"seed": seed, "length_km": case.line.length_m / 1000.0, "factor": factor, "time_s": t,
                   "end_ms": case.final_speed_ms, "energy_kwh": tr.energy.net_kwh + lam * (tr.running_time_s - t) / J_PER_KWH,
                   "bound_kwh": tr.summary["energy_bound_kwh"], "traction_kwh": tr.energy.traction_kwh,
                   "end_error_ms": abs(tr.speed_ms[-1] - case.final_speed_ms), "cpu_s": cpu, "features": features}
            for n in intervals if checkout is not None else ():
                energy, cpu_m, v_end = (mseetc_cached(cache[n], seed, case, t, n, None, python, repeats) if n in cache
                                        else mseetc_cached([], seed, case, t, n, checkout, python, repeats))
                row[f"ms{n}_kwh"], row[f"ms{n}_cpu_s"], row[f"ms{n}_end_ms"] = energy, cpu_m, v_end
            rows.append(row)
            print({k: (round(v, 4) if isinstance(v, float) else v) for k, v in row.items() if k != "features"},
                  flush=True)
    return pd.DataFrame(rows)


def generated_summary(table: pd.DataFrame, intervals: tuple[int, ...]) -> list[str]:
    """Differences in % of traction energy, CPU ratios and every certificate violation, as report lines."""
    out = []
    if not intervals or f"ms{max(intervals)}_kwh" not in table:
        return ["(ms-eetc not run)"]
    best = f"ms{max(intervals)}_kwh"
    ok = table[best].notna()
    lines = table.groupby("seed").first()
    out.append(f"- {len(lines)} lines: {int(lines.features.str.contains('descent').sum())} with long descents under"
               f" limits, {int((lines.end_ms > 1.0).sum())} with ends at more than ms-eetc's 1 m/s")
    diff = 100.0 * (table["energy_kwh"] - table[best]) / table["traction_kwh"]
    out.append(f"- {int(ok.sum())} answers with ms-eetc N={max(intervals)}; pymoo-rail minus ms-eetc in % of"
               f" pymoo-rail's traction energy: median {diff[ok].median():+.4f} %, range {diff[ok].min():+.4f} .."
               f" {diff[ok].max():+.4f} %; median |difference| {diff[ok].abs().median():.4f} %")
    if "ms300_cpu_s" in table:
        ratio = table["ms300_cpu_s"] / table["cpu_s"]
        out.append(f"- CPU ratio ms-eetc N=300 / pymoo-rail: median {ratio.median():.1f}x (range {ratio.min():.1f} .."
                   f" {ratio.max():.1f}x)")
    out.append(f"- end speed: largest |pymoo-rail's arrival speed - asked| = {table['end_error_ms'].max():.2e} m/s")
    violations = table[ok & (table[best] < table["energy_kwh"] - table["bound_kwh"])]
    out.append(f"- certificate violations (ms-eetc N={max(intervals)} below pymoo-rail's energy minus its"
               f" certificate): {len(violations)}")
    for _, v in violations.iterrows():
        out.append(f"  - seed {int(v.seed)} at {v.factor} x: pymoo-rail {v.energy_kwh:.3f} +- {v.bound_kwh:.3f},"
                   f" ms-eetc {v[best]:.3f} kWh ({v.features})")
    return out


def refresh_cached(table: pd.DataFrame, cache: dict[int, list[Path]]) -> pd.DataFrame:
    """``table`` (of :func:`generated_rows`) with the columns of the cached N read again from the caches."""
    table = table.copy()
    for n, caches in cache.items():
        for i, row in table.iterrows():
            case = comparable_case(int(row.seed))
            energy, cpu, v_end = mseetc_cached(caches, int(row.seed), case, float(row.time_s), n, None, "", 1)
            table.loc[i, [f"ms{n}_kwh", f"ms{n}_cpu_s", f"ms{n}_end_ms"]] = energy, cpu, v_end
    return table




def warm_up() -> None:
    """Solve a small case once so that the Numba cache is loaded before anything is timed."""
    from pymoo_rail.cases import load_case
    from pymoo_rail.optimal import OptimalSolver

    OptimalSolver(load_case("yizhuang"), n_speeds=20).profile(150.0)


def named_rows(cases, checkout: Path | None, python: str,
               breakdown: bool = False) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """pymoo-rail on named cases beside ms-eetc (run here or recorded), GPOPS-II and the closed form.

    Parameters
    ----------
    cases : sequence of (str, float, str or None)
        Case name or file, running time (s) and ms-eetc's track id (None: no ms-eetc run).
    checkout : pathlib.Path or None
        An ms-eetc checkout to run here; None: its figures recorded on this machine (``MSEETC_RECORDED``).
    python : str
        The interpreter with ms-eetc's dependencies.
    breakdown : bool
        Also where pymoo-rail's CPU time goes (:func:`cpu_breakdown`, a second run under cProfile).

    Returns
    -------
    tuple of pandas.DataFrame
        pymoo-rail's rows (:func:`pymoo_rail_row`), the peers' rows and the CPU breakdown (empty without).
    """
    rows, peers, parts = [], [], []
    for name, t, track_id in cases:
        row = pymoo_rail_row(name, t)
        rows.append(row)
        print(row, flush=True)
        if breakdown:
            parts.append(cpu_breakdown(name, t))
            print(parts[-1], flush=True)
        if track_id is None:
            continue
        for n in (100, 300, 1000):
            if checkout is not None:
                energy, cpu = run_mseetc(checkout, python, track_id, t, n)
                source = "run here"
            elif (row["case"], n) in MSEETC_RECORDED:
                energy, cpu = MSEETC_RECORDED[(row["case"], n)]
                source = f"recorded {MSEETC_DATE}"
            else:
                continue
            peers.append({"case": row["case"], "solver": f"ms-eetc N={n}", "energy_kwh": energy, "cpu_s": cpu,
                          "source": source})
        if row["case"] in GPOPS_II:
            energy, cpu = GPOPS_II[row["case"]]
            peers.append({"case": row["case"], "solver": "GPOPS-II", "energy_kwh": energy, "cpu_s": cpu,
                          "source": "published"})
    return pd.DataFrame(rows), pd.DataFrame(peers), pd.DataFrame(parts)
