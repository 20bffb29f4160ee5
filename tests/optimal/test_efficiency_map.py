"""The exact solver with an efficiency map: a constant map changes nothing, the holding speeds
solve the stationarity condition with the map, and the optimum under the map beats the runs planned
under constant efficiencies when all are costed under the map."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import EfficiencyMap
from pymoo_rail.optimal import OptimalSolver
from pymoo_rail.optimal.dp import hold_stationarity, map_hold_speed, psi_speed, singular_speeds
from pymoo_rail.sim import Simulator
from tests.optimal.cases import level_case

# efficiency rising linearly with speed, the same at every force (bilinear is exact on it)
E0, E1, V1_KMH = 0.6, 0.9, 100.0
SPEED_MAP = EfficiencyMap((0.0, V1_KMH), (0.0, 300.0), ((E0, E0), (E1, E1)))


def _mapped(case, traction_map, regen_map=None):
    train = replace(case.train, traction_efficiency=traction_map.peak, traction_efficiency_map=traction_map)
    if regen_map is not None:
        train = replace(train, regen_efficiency=regen_map.peak, regen_efficiency_map=regen_map)
    return replace(case, train=train)


def test_a_constant_map_gives_the_same_optimum_bit_for_bit():
    case = level_case(traction_efficiency=0.85, regen_efficiency=0.7)
    flat = EfficiencyMap((0.0, 100.0), (0.0, 300.0), ((0.85, 0.85), (0.85, 0.85)))
    flat_regen = EfficiencyMap((0.0, 100.0), (0.0, 300.0), ((0.7, 0.7), (0.7, 0.7)))
    plain = OptimalSolver(case, certify=False).profile(300.0)
    mapped = OptimalSolver(_mapped(case, flat, flat_regen), certify=False).profile(300.0)
    assert np.array_equal(plain.speed_ms, mapped.speed_ms) and np.array_equal(plain.force_n, mapped.force_n)
    assert plain.energy == mapped.energy


def test_holding_speed_solves_the_stationarity_condition_with_the_map():
    # level track, F = R(V): g = F / eta(V), so V^2 (R'(V) / eta(V) - R(V) eta'(V) / eta(V)^2) = lambda + P_aux
    case = _mapped(level_case(), SPEED_MAP)
    m = Simulator(case).model
    slope = (E1 - E0) / (V1_KMH / KMH_PER_MS)

    def condition(v, price):
        r, r_prime, eta = m.davis_a_n + m.davis_b_nsm * v + m.davis_c_ns2m2 * v * v, m.davis_b_nsm + 2 * m.davis_c_ns2m2 * v, E0 + slope * v
        return v * v * (r_prime / eta - r * slope / eta ** 2) - price

    for price in (20e3, 40e3, 80e3):
        v = map_hold_speed(m, price, 0.0, False, 30.0)
        assert v == pytest.approx(brentq(condition, 1.0, 27.0, args=(price,), xtol=1e-12), rel=1e-6)
    # a constant map: the condition is psi(v) / eta, the closed form's
    flat = Simulator(_mapped(level_case(), EfficiencyMap((0.0, 100.0), (0.0, 300.0), ((0.8, 0.8), (0.8, 0.8))))).model
    v = psi_speed(flat.davis_b_nsm, flat.davis_c_ns2m2, 0.8 * 40e3)
    assert hold_stationarity(flat, v, 0.0, False) == pytest.approx(40e3, rel=1e-9)
    # the DP takes them as its singular speeds
    n = m.position_m.shape[0]
    sing_v, sing_p = np.zeros((n, 2)), np.zeros((n, 2))
    singular_speeds(m, np.full(n - 1, 40e3), 150, 0.0, sing_v, sing_p)
    assert sing_v[n // 2, 0] == map_hold_speed(m, 40e3, 0.0, False, m.envelope_ms[n // 2])


def test_the_optimum_under_the_map_beats_constant_plans_costed_under_the_map():
    # the efficiency falls with force: gentle traction pays, which constant efficiencies ignore
    falling = EfficiencyMap((0.0, 50.0, 100.0), (0.0, 50.0, 100.0),
                            ((0.9, 0.8, 0.55), (0.92, 0.85, 0.6), (0.93, 0.86, 0.62)))
    case = _mapped(level_case(), falling)
    judge = Simulator(case)
    mapped = OptimalSolver(case, certify=False).profile(330.0)
    costs = {}
    for eta in (0.6, 0.9):
        plan = OptimalSolver(level_case(traction_efficiency=eta), certify=False).profile(330.0)
        # at the same running time to within the price of the difference
        shift = mapped.summary["lambda_w"] * (plan.running_time_s - mapped.running_time_s) / 3.6e6
        costs[eta] = judge.energy_of(plan).net_kwh + shift
    assert mapped.energy.net_kwh < min(costs.values())
    assert abs(mapped.running_time_s - 330.0) < 1.0


def test_a_profile_costed_from_its_points_is_the_simulators_energy():
    from pymoo_rail.optimal.efficiency_study import profile_energy_kwh
    from pymoo_rail.sim import switching_programs

    falling = EfficiencyMap((0.0, 50.0, 100.0), (0.0, 50.0, 100.0),
                            ((0.9, 0.8, 0.55), (0.92, 0.85, 0.6), (0.93, 0.86, 0.62)))
    case = _mapped(level_case(aux_power_kw=40.0, regen_efficiency=0.8), falling)
    run = Simulator(case, dx_m=1.0).run(switching_programs([1500.0, 3500.0], ("traction", "coast", "brake"),
                                                           5000.0)[0])
    # every 20th node: another solver's coarser points
    pick = np.r_[np.arange(0, run.position_m.shape[0] - 1, 20), run.position_m.shape[0] - 1]
    costed = profile_energy_kwh(case, run.position_m[pick], run.speed_ms[pick], run.time_s[pick])
    assert costed == pytest.approx(run.energy.net_kwh, rel=2e-3)
    assert costed != pytest.approx(run.energy.net_kwh - run.energy.aux_kwh, rel=2e-3)  # auxiliaries counted


def test_regen_holding_condition_with_a_map():
    # braking on a descent: g = -eta_r(v) |F|, so the condition is V^2 (R' (eta_r + 0) - |F| eta_r'(V))
    regen = EfficiencyMap((0.0, V1_KMH), (0.0, 300.0), ((0.5, 0.5), (0.8, 0.8)))
    case = replace(level_case(), train=replace(level_case().train, regen_efficiency=0.8, regen_efficiency_map=regen))
    m = Simulator(case).model
    slope = (0.8 - 0.5) / (V1_KMH / KMH_PER_MS)
    line_n = -60_000.0  # a descent steeper than the resistance at these speeds: braking holds
    for v in (10.0, 20.0):
        r = m.davis_a_n + m.davis_b_nsm * v + m.davis_c_ns2m2 * v * v
        r_prime, eta = m.davis_b_nsm + 2 * m.davis_c_ns2m2 * v, 0.5 + slope * v
        expected = v * v * (r_prime * eta - abs(r + line_n) * slope)
        assert hold_stationarity(m, v, line_n, True) == pytest.approx(expected, rel=1e-6)
