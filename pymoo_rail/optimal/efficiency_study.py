"""Optimal runs planned under different efficiency models, each costed under the most detailed one.

The study of Kouzoupis et al. (ms-eetc, Transportation Research Part C 2023, fig. 5): the same train
and track, the optimal run planned with perfect efficiency (1 both ways), with a static efficiency
(a constant both ways) and with the dynamic one (losses at the operating point: motor and
converter maps, gear, transformer, auxiliaries), each run then costed under the dynamic model,
the energy it really draws. ``benchmarks/efficiency_study.py`` runs it beside ms-eetc.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import Case, EfficiencyMap
from pymoo_rail.optimal.solver import OptimalSolver
from pymoo_rail.sim import Simulator

# ms-eetc's simulations/figure5.py: the first 8.5 km of track 00_var_speed_limit_100, from 1 m/s to
# 100 km/h, time reserves over its minimum time, the static 73 % and the dynamic model's parts
STUDY_LENGTH_M = 8500.0
STUDY_FINAL_SPEED_KMH = 100.0
STUDY_MIN_TIME_S = 272.4726
TIME_RESERVES_PCT = (0.0, 10.0, 20.0, 30.0)
STATIC_EFFICIENCY = 0.73
AUX_POWER_KW = 27.0
GEAR_EFFICIENCY = 0.96
MODELS = ("perfect", "static", "dynamic")


def study_case(base: Case, length_m: float = STUDY_LENGTH_M, final_speed_kmh: float = STUDY_FINAL_SPEED_KMH) -> Case:
    """The first ``length_m`` of ``base``'s line, run to ``final_speed_kmh`` (ms-eetc's fig. 5 set-up)."""
    return replace(base, name=f"{base.name}-{length_m / 1000.0:g}km", line=base.line.slice(0.0, length_m),
                   final_speed_ms=final_speed_kmh / KMH_PER_MS)


def loss_grid(max_speed_kmh: float, max_force_kn: float) -> tuple[np.ndarray, np.ndarray]:
    """Speeds (km/h) and forces (kN) at which a loss model is sampled for the maps: every 2 km/h from
    1 km/h, and forces dense near zero, where the efficiency ``F v / (F v + loss)`` bends most."""
    speeds = np.concatenate(([1.0], np.arange(2.0, max_speed_kmh + 1e-9, 2.0)))
    forces = np.unique(np.concatenate((np.geomspace(0.25, 10.0, 12), np.linspace(10.0, max_forces(max_force_kn), 41))))
    return speeds, forces


def max_forces(max_force_kn: float) -> float:
    """The top force node of :func:`loss_grid`: the train's largest force, rounded up to 0.1 kN."""
    return float(np.ceil(max_force_kn * 10.0) / 10.0)


def operating_forces_kn(case: Case, speeds_kmh: np.ndarray, forces_kn: np.ndarray) -> np.ndarray:
    """``forces_kn`` at each speed, held at the traction curve where a node lies beyond it (a loss
    model has no losses there; the map then holds the curve's efficiency, and the train never uses
    those nodes but interpolates towards them). Shape (speeds, forces)."""
    curve = case.train.traction.force_kn(speeds_kmh) * (1.0 - 1e-9)
    return np.minimum(forces_kn[None, :], curve[:, None])


def efficiency_models(case: Case, traction_map: EfficiencyMap, regen_map: EfficiencyMap,
                      aux_power_kw: float = AUX_POWER_KW, static: float = STATIC_EFFICIENCY) -> dict[str, Case]:
    """The case's train under the three models: ``perfect`` (1 both ways, no auxiliaries),
    ``static`` (``static`` both ways, none) and ``dynamic`` (the maps and ``aux_power_kw``)."""
    train = replace(case.train, traction_efficiency_map=None, regen_efficiency_map=None, aux_power_kw=0.0)
    trains = {"perfect": replace(train, traction_efficiency=1.0, regen_efficiency=1.0),
              "static": replace(train, traction_efficiency=static, regen_efficiency=static),
              "dynamic": replace(train, traction_efficiency=traction_map.peak, regen_efficiency=regen_map.peak,
                                 traction_efficiency_map=traction_map, regen_efficiency_map=regen_map,
                                 aux_power_kw=aux_power_kw)}
    return {name: replace(case, name=f"{case.name}-{name}", train=t) for name, t in trains.items()}


def planned_runs(models: dict[str, Case], running_time_s: float, costed_under: str = "dynamic") -> list[dict]:
    """The optimal run of each model at ``running_time_s``, its energy under its own model and under
    ``costed_under`` (kWh), its running time, the CPU time of its solve (``cpu_s``) and the run itself (``run``)."""
    judge = Simulator(models[costed_under])
    rows = []
    for name, case in models.items():
        started = time.process_time()
        run = OptimalSolver(case).profile(running_time_s)
        cpu_s = time.process_time() - started
        real = judge.energy_of(run)
        rows.append({"model": name, "running_time_s": run.running_time_s, "own_kwh": run.energy.net_kwh, "cpu_s": cpu_s,
                     f"{costed_under}_kwh": real.net_kwh, f"{costed_under}_traction_kwh": real.traction_kwh,
                     f"{costed_under}_regen_kwh": real.regen_kwh, f"{costed_under}_aux_kwh": real.aux_kwh,
                     "run": run})
    return rows


def profile_forces_n(case: Case, position_m, speed_ms) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The force at the wheel of each interval of a speed profile given at its own points (another
    solver's run): ``F = M (v1^2 - v0^2) / (2 d) + R(v) + line force`` at its mean speed and its middle.
    Returns ``(force_n, mean_speed_ms, length_m)``, one per interval."""
    x, v = np.asarray(position_m, dtype=float), np.asarray(speed_ms, dtype=float)
    train = case.train
    a, b, c = train.resistance.coefficients_si(train.mass_kg)
    grid = Simulator(case).grid
    d, v_mid, x_mid = np.diff(x), 0.5 * (v[1:] + v[:-1]), 0.5 * (x[1:] + x[:-1])
    cell = np.minimum((x_mid / grid.dx_m).astype(int), grid.line_force_n.shape[0] - 1)
    force = (train.effective_mass_kg * (v[1:] ** 2 - v[:-1] ** 2) / (2.0 * d) + a + b * v_mid + c * v_mid ** 2
             + grid.line_force_n[cell])
    return force, v_mid, d


def part_power_km(case: Case, position_m, speed_ms, below: float = 0.95, min_accel_ms2: float = 0.02) -> float:
    """How far a speed profile accelerates at part power (km): intervals pulling with a force below ``below``
    x the traction curve at their mean speed (:func:`profile_forces_n`) and accelerating at least at
    ``min_accel_ms2`` (not holding a speed: a solver's holding arc gains or loses a little speed)."""
    force, v_mid, d = profile_forces_n(case, position_m, speed_ms)
    curve_n = case.train.traction.force_kn(v_mid * KMH_PER_MS) * 1000.0
    v = np.asarray(speed_ms, dtype=float)
    accelerating = (v[1:] ** 2 - v[:-1] ** 2) / (2.0 * d) >= min_accel_ms2
    return float(d[(force > 0.0) & accelerating & (force < below * curve_n)].sum() / 1000.0)


def profile_energy_kwh(case: Case, position_m, speed_ms, time_s) -> float:
    """Net energy (kWh) of a speed profile given at its own points (another solver's run) under the
    case's train: the force of each interval (:func:`profile_forces_n`) drawn as ``F d / eta`` when
    pulling and returned as ``eta |F| d`` when braking (all braking electric: the study's train has no
    regen caps), plus the auxiliary power over the run's time."""
    t = np.asarray(time_s, dtype=float)
    train = case.train
    force, v_mid, d = profile_forces_n(case, position_m, speed_ms)
    speed_kmh, force_kn = v_mid * KMH_PER_MS, force / 1000.0
    eta_t = (train.traction_efficiency_map.efficiency(speed_kmh, force_kn) if train.traction_efficiency_map
             is not None else np.full(force.shape, train.traction_efficiency))
    eta_r = (train.regen_efficiency_map.efficiency(speed_kmh, force_kn) if train.regen_efficiency_map
             is not None else np.full(force.shape, train.regen_efficiency))
    work = force * d
    electric_j = np.where(force > 0.0, work / eta_t, eta_r * work).sum()
    return float((electric_j + train.aux_power_kw * 1000.0 * (t[-1] - t[0])) / J_PER_KWH)
