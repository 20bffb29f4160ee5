"""Efficiency at the operating point in the simulator: work balance, constant map, closed form."""

import dataclasses
import math

import numpy as np
import pytest

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import EfficiencyMap
from pymoo_rail.sim import Simulator, switching_programs
from pymoo_rail.sim import kernel as k
from tests.conftest import make_case

SPEEDS_KMH = (0.0, 40.0, 80.0, 120.0)
FORCES_KN = (0.0, 60.0, 300.0)
VALUES = ((0.55, 0.70, 0.75), (0.70, 0.85, 0.88), (0.78, 0.90, 0.92), (0.80, 0.91, 0.93))


def _with(case, **train):
    return dataclasses.replace(case, train=dataclasses.replace(case.train, **train))


def _random_programs(sim, n=24, seed=5):
    programs = np.random.default_rng(seed).uniform(0.0, 1.0, (n, 6, 3))
    programs[:, :, 0] = np.sort(programs[:, :, 0], axis=1) * sim.length_m
    programs[:, -1, 0] = sim.length_m
    programs[:, :, 1] = np.floor(programs[:, :, 1] * 6)  # every mode but decel/stop
    programs[:, :, 2] *= 30.0
    return programs


@pytest.mark.parametrize("name", ["yizhuang", "wuguang-crh3"])
def test_constant_map_equals_the_constant_efficiency_bit_for_bit(name):
    from pymoo_rail.cases import load_case

    case = _with(load_case(name), traction_efficiency=0.85, regen_efficiency=0.7)
    flat = EfficiencyMap((0.0, 150.0, 400.0), FORCES_KN, tuple((0.85,) * 3 for _ in range(3)))
    flat_regen = EfficiencyMap((0.0, 400.0), (0.0, 1000.0), ((0.7, 0.7), (0.7, 0.7)))
    mapped = _with(case, traction_efficiency_map=flat, regen_efficiency_map=flat_regen)
    plain_sim, map_sim = Simulator(case), Simulator(mapped)
    programs = _random_programs(plain_sim)
    plain, with_map = plain_sim.run_batch(programs), map_sim.run_batch(programs)
    assert plain[:, k.OUT_REGEN_KWH].max() > 0.0  # the programs do regenerate
    assert np.array_equal(plain, with_map)
    a, b = plain_sim.run(programs[0]), map_sim.run(programs[0])
    assert a.summary == b.summary


def test_electrical_energy_is_the_work_over_the_map_cell_by_cell():
    tmap = EfficiencyMap(SPEEDS_KMH, FORCES_KN, VALUES)
    rmap = EfficiencyMap(SPEEDS_KMH, FORCES_KN, tuple(tuple(0.9 * x for x in row) for row in VALUES))
    case = make_case(train={"traction_efficiency_map": {"speeds_kmh": list(SPEEDS_KMH), "forces_kn": list(FORCES_KN),
                                                        "values": [list(r) for r in VALUES]},
                            "regen_efficiency_map": {"speeds_kmh": list(SPEEDS_KMH), "forces_kn": list(FORCES_KN),
                                                     "values": [list(r) for r in rmap.values]},
                            "resistance": {"a": 2.0, "b": 0.0, "c": 0.005, "unit": "kN", "speed_unit": "ms"}},
                     line={"gradients": [[0.0, 1000.0, 5.0], [1000.0, 2000.0, -8.0]]})
    assert case.train.traction_efficiency_map == tmap and case.train.traction_efficiency == 0.93
    sim = Simulator(case, dx_m=5.0)
    for program in switching_programs([700.0, 1200.0], ("traction", "hold_brake", "brake"), 2000.0):
        tr = sim.run(program)
        x, v, f = tr.position_m, tr.speed_ms, tr.force_n[:-1]
        d, vm_kmh = np.diff(x), 0.5 * (v[1:] + v[:-1]) * KMH_PER_MS
        trac = np.where(f > 0, f * d / tmap.efficiency(vm_kmh, f / 1000.0), 0.0).sum()
        regen = np.where(f < 0, -f * d * rmap.efficiency(vm_kmh, f / 1000.0), 0.0).sum()
        assert tr.summary["traction_kwh"] * J_PER_KWH == pytest.approx(trac, rel=1e-11)
        assert tr.summary["regen_kwh"] * J_PER_KWH == pytest.approx(regen, rel=1e-11)
        assert regen > 0.0
        # the mechanical balance is untouched by the map
        s = tr.summary
        assert s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] == pytest.approx(
            0.0, abs=1e-6 * s["traction_work_j"])
        cell_trac, cell_regen = k.trace_cell_energies(sim.model, x, v, tr.force_n)
        assert cell_trac.sum() == pytest.approx(trac, rel=1e-11)
        assert cell_regen.sum() == pytest.approx(regen, rel=1e-11)


def test_speed_dependent_map_closed_form_on_level_track():
    # F constant, no resistance: dx = M v dv / F, so E = int F dx / eta(v) = M int v dv / (e0 + s v)
    # = M / s^2 [s V - e0 ln(1 + s V / e0)], with eta linear in v (bilinear is exact on it)
    e0, top = 0.6, 0.9
    v_top_ms = 120.0 / KMH_PER_MS
    slope = (top - e0) / v_top_ms
    values = [[e0, e0], [top, top]]
    case = make_case(train={"max_speed_kmh": 120.0,
                            "traction_efficiency_map": {"speeds_kmh": [0.0, 120.0], "forces_kn": [0.0, 200.0],
                                                        "values": values}},
                     line={"speed_limits": [[0.0, 2000.0, 120.0]]})
    tr = Simulator(case, dx_m=0.25).run(switching_programs([400.0], ("traction", "coast"), 2000.0)[0])
    m_eff = case.train.effective_mass_kg
    v_end = math.sqrt(2.0 * 100_000.0 * 400.0 / m_eff)
    expected = m_eff / slope ** 2 * (slope * v_end - e0 * math.log(1.0 + slope * v_end / e0))
    assert tr.summary["traction_kwh"] * J_PER_KWH == pytest.approx(expected, rel=1e-5)  # midpoint rule, dx = 0.25 m
    # peak power: the last traction cell's F v / eta(v)
    assert tr.summary["peak_traction_kw"] == pytest.approx(100.0 * v_end / (e0 + slope * v_end), rel=1e-3)


def test_problems_and_tracking_account_with_the_map():
    from pymoo_rail.cases import load_case
    from pymoo_rail.control import PID, track
    from pymoo_rail.problems import SpeedProfileProblem

    base = _with(load_case("yizhuang"), traction_efficiency=0.85, regen_efficiency=0.7)
    tmap = EfficiencyMap((0.0, 40.0, 80.0), (0.0, 100.0, 300.0),
                         ((0.5, 0.7, 0.8), (0.6, 0.8, 0.85), (0.62, 0.82, 0.85)))
    mapped = _with(base, traction_efficiency=0.85, traction_efficiency_map=tmap)
    problem = SpeedProfileProblem(mapped)
    x = np.random.default_rng(2).uniform(problem.xl, problem.xu, problem.n_var)
    run = problem.trajectory(x)
    x_m, v, f = run.position_m, run.speed_ms, run.force_n[:-1]
    d, vm_kmh = np.diff(x_m), 0.5 * (v[1:] + v[:-1]) * KMH_PER_MS
    expected = np.where(f > 0, f * d / tmap.efficiency(vm_kmh, f / 1000.0), 0.0).sum()
    assert run.summary["traction_kwh"] * J_PER_KWH == pytest.approx(expected, rel=1e-11)
    # the tracking layer drives the same kernel accounting: a map at or below the constant costs more
    plain, with_map = track(base, run, PID()), track(mapped, run, PID())
    assert with_map.summary["traction_work_j"] == plain.summary["traction_work_j"]
    assert with_map.summary["traction_kwh"] > plain.summary["traction_kwh"]
    tr_x, tr_v, tr_f = with_map.position_m, with_map.speed_ms, with_map.force_n[:-1]
    d, vm_kmh = np.diff(tr_x), 0.5 * (tr_v[1:] + tr_v[:-1]) * KMH_PER_MS
    tracked = np.where(tr_f > 0, tr_f * d / tmap.efficiency(vm_kmh, tr_f / 1000.0), 0.0).sum()
    assert with_map.summary["traction_kwh"] * J_PER_KWH == pytest.approx(tracked, rel=1e-9)


def test_kernel_interpolation_is_the_models_inside_and_beyond_the_table():
    from pymoo_rail.sim.physics import map_efficiency

    tmap = EfficiencyMap(SPEEDS_KMH, FORCES_KN, VALUES)
    speeds, forces, values = tmap.table_si()
    rng = np.random.default_rng(11)
    v_kmh, f_kn = rng.uniform(-10.0, 160.0, 200), rng.uniform(-400.0, 400.0, 200)
    v_kmh[:4] = SPEEDS_KMH  # on the nodes too
    kernel = [map_efficiency(speeds, forces, values, v / KMH_PER_MS, f * 1000.0) for v, f in zip(v_kmh, f_kn)]
    assert np.allclose(kernel, tmap.efficiency(v_kmh, f_kn), rtol=1e-12, atol=0.0)


def test_energy_of_a_run_under_its_own_train_is_its_summary():
    tmap = EfficiencyMap(SPEEDS_KMH, FORCES_KN, VALUES)
    case = _with(make_case(train={"aux_power_kw": 50.0, "regen_efficiency": 0.8}), traction_efficiency=0.93,
                 traction_efficiency_map=tmap)
    sim = Simulator(case, dx_m=2.0)
    run = sim.run(switching_programs([900.0], ("traction", "brake"), 2000.0)[0])
    replayed = sim.energy_of(run)
    for name in ("traction_kwh", "regen_kwh", "aux_kwh", "net_kwh"):
        assert getattr(replayed, name) == pytest.approx(getattr(run.energy, name), rel=1e-12)
    # under a constant-efficiency train the same run costs the work over that efficiency
    plain = Simulator(_with(case, traction_efficiency=0.5, traction_efficiency_map=None), dx_m=2.0).energy_of(run)
    assert plain.traction_kwh * J_PER_KWH == pytest.approx(run.summary["traction_work_j"] / 0.5, rel=1e-12)
