"""Part-power traction in the exact solver: where the traction efficiency falls with the force,
pulling gently beats full traction then holding and coasting (a brute force over that family
shows it, the DP finds it), the replay is exact, and a case without a varying map is untouched."""

import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import EfficiencyMap
from pymoo_rail.optimal import OptimalSolver, dp
from pymoo_rail.sim import Simulator
from pymoo_rail.sim import kernel as k
from tests.optimal.cases import level_case

# the efficiency falls from ~0.85 at half force to ~0.6 at full force (the loss grows faster than the power)
FALLING = EfficiencyMap((0.0, 50.0, 100.0), (0.0, 50.0, 100.0),
                        ((0.9, 0.8, 0.55), (0.92, 0.85, 0.6), (0.93, 0.86, 0.62)))
RUNNING_TIME_S = 330.0
DX_M = 5.0


def _mapped(case, traction_map):
    return replace(case, train=replace(case.train, traction_efficiency=traction_map.peak,
                                       traction_efficiency_map=traction_map))


@pytest.fixture(scope="module")
def falling_case():
    return _mapped(level_case(), FALLING)


@pytest.fixture(scope="module")
def optimum(falling_case):
    return OptimalSolver(falling_case, dx_m=DX_M, certify=False).profile(RUNNING_TIME_S)


def _family_best_kwh(sim, shares, speeds_kmh, n_coast=80):
    """Least energy at RUNNING_TIME_S over the runs 'pull at a share up to V and hold it, coast from x_c
    to the platform' (the envelope brakes onto it), per share: x_c interpolated onto the time, best V."""
    coast_m = np.linspace(300.0, sim.length_m - 50.0, n_coast)
    best = {}
    for share in shares:
        energies = []
        for v_kmh in speeds_kmh:
            programs = np.zeros((n_coast, 2, 4))
            programs[:, 0] = (0.0, k.MODE_TOWARD, v_kmh / KMH_PER_MS, share)
            programs[:, 1] = (sim.length_m, k.MODE_COAST, 0.0, 1.0)
            programs[:, 0, 0] = coast_m
            out = sim.run_batch(programs)
            ok = out[:, k.OUT_REACHED] > 0
            t, e = out[ok, k.OUT_RUNNING_TIME_S], out[ok, k.OUT_NET_KWH]
            if t.size > 1 and t.min() <= RUNNING_TIME_S <= t.max():
                order = np.argsort(t)
                energies.append(float(np.interp(RUNNING_TIME_S, t[order], e[order])))
        best[share] = min(energies, default=np.inf)
    return best


def test_part_power_beats_full_traction_hold_and_coast_and_the_dp_finds_it(falling_case, optimum):
    sim = Simulator(falling_case, dx_m=DX_M)
    best = _family_best_kwh(sim, (0.4, 0.5, 0.6, 1.0), np.arange(60.0, 100.0, 2.5))
    part = min(v for s, v in best.items() if s < 1.0)
    # pulling at part of the force is clearly cheaper than the same family at full traction
    assert part < 0.97 * best[1.0]
    # the DP's optimum, at the requested time to first order, is at least as good as the family's best
    moved = optimum.energy.net_kwh + optimum.summary["lambda_w"] * (optimum.running_time_s - RUNNING_TIME_S) / J_PER_KWH
    assert moved <= part * 1.002
    # ... and it pulls at part force for much of its acceleration
    v_kmh = optimum.speed_ms[:-1] * KMH_PER_MS
    f_max = falling_case.train.traction.force_kn(v_kmh) * 1000.0
    partial = (optimum.force_n[:-1] > 0.0) & (optimum.force_n[:-1] < 0.95 * f_max) & (optimum.accel_ms2[:-1] > 0.02)
    assert partial.sum() * DX_M > 300.0


def test_the_old_controls_alone_cost_more_at_the_same_price(falling_case, monkeypatch):
    # the DP over the larger control set never does worse in energy + lambda x time
    solver = OptimalSolver(falling_case, dx_m=DX_M, certify=False)
    with_part = solver.solve_price(30e3)
    assert with_part.program.shape[1] == 4 and np.any((with_part.program[:, 3] > 0) & (with_part.program[:, 3] < 1))
    monkeypatch.setattr(dp, "PART_POWER_SHARES", np.empty(0))
    without = OptimalSolver(falling_case, dx_m=DX_M, certify=False).solve_price(30e3)
    assert without.program.shape[1] == 3
    cost = lambda s: s.energy_j + s.lambda_w * s.time_s  # noqa: E731
    assert cost(with_part) < cost(without) - 0.01 * with_part.energy_j


def test_the_replay_of_a_part_power_run_balances_its_work_and_energy(falling_case, optimum):
    # the solver's own check passed (speeds to 1e-9 m/s, energy to 1e-9); the run is the simulator's
    x, v, f = optimum.position_m, optimum.speed_ms, optimum.force_n[:-1]
    d, vm_kmh = np.diff(x), 0.5 * (v[1:] + v[:-1]) * KMH_PER_MS
    electric = np.where(f > 0, f * d / FALLING.efficiency(vm_kmh, f / 1000.0), 0.0).sum()
    assert optimum.energy.traction_kwh * J_PER_KWH == pytest.approx(electric, rel=1e-11)
    s = optimum.summary
    kinetic = 0.5 * falling_case.train.effective_mass_kg * (v[-1] ** 2 - v[0] ** 2)
    assert s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] == pytest.approx(
        kinetic, abs=1e-6 * s["traction_work_j"])
    assert optimum.stop_error_m == pytest.approx(0.0, abs=1e-6) and abs(optimum.running_time_s - RUNNING_TIME_S) < 0.5


def test_no_varying_map_no_part_power():
    plain = Simulator(level_case(traction_efficiency=0.85), dx_m=DX_M).model
    flat = EfficiencyMap((0.0, 100.0), (0.0, 300.0), ((0.85, 0.85), (0.85, 0.85)))
    constant = Simulator(_mapped(level_case(), flat), dx_m=DX_M).model
    for m in (plain, constant):
        assert dp.part_power_shares(m).shape == (0,)
        assert dp.transitions(m, 20, 4, 0.5)[1].shape[2] == dp.N_FIXED


def test_a_case_without_a_map_compiles_no_part_power_kernel():
    # a fresh interpreter: the part-power kernels stay uncompiled (nor loaded from the cache) after an optimum
    code = ("from pymoo_rail.optimal import OptimalSolver, dp\n"
            "from tests.optimal.cases import level_case\n"
            "OptimalSolver(level_case(), dx_m=20.0, n_speeds=30, certify=False).profile(330.0)\n"
            "names = ('forward_rollout_part_power', '_fill_part_power', 'best_part_power', 'part_power_outcome')\n"
            "print(sum(len(getattr(dp, n).signatures) for n in names))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "0"


def test_part_power_distance_of_a_profile_from_its_points(falling_case):
    from pymoo_rail.optimal.efficiency_study import part_power_km

    sim = Simulator(falling_case, dx_m=1.0)
    program = np.array([[3000.0, k.MODE_TOWARD, 80.0 / KMH_PER_MS, 0.5], [5000.0, k.MODE_COAST, 0.0, 1.0]])
    gentle = sim.run(program)
    program[0, 3] = 1.0
    full = sim.run(program)
    # every 10th point: another solver's coarser points
    gentle_km = part_power_km(falling_case, gentle.position_m[::10], gentle.speed_ms[::10])
    pulling = (gentle.force_n[:-1] > 0) & (np.diff(gentle.speed_ms) > 0)
    assert gentle_km == pytest.approx(pulling.sum() / 1000.0, rel=0.02) and gentle_km > 0.5
    assert part_power_km(falling_case, full.position_m[::10], full.speed_ms[::10]) < 0.02
