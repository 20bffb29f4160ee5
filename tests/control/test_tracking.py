"""Tracked runs obey the physics, reproduce drivable references and stop at the platform."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pymoo_rail.control import PID, FuzzyPID, Hysteresis, Tracker, track
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs, switching_programs
from pymoo_rail.sim.kernel import OUT_NAMES, REGIME_BRAKE, REGIME_COAST, REGIME_CRUISE, REGIME_TRACTION
from tests.conftest import make_case

from .conftest import cruise_reference

CONTROLLERS = [Hysteresis(2.0, 3.0), Hysteresis(2.0, 6.0), PID(), FuzzyPID()]


def _limit_under_train(line, train_length_m, x):
    """Lowest limit anywhere under a train whose head is at x (independent of the grid code).

    A zone binds while the tail is strictly inside it (the instant the tail leaves is free).
    """
    lo = max(0.0, x - train_length_m)
    return min(v for s, e, v in line.speed_limits if s <= x and e > lo) / 3.6


def _check_physics(case, tr):
    assert np.all(np.isfinite(tr.speed_ms)) and np.all(tr.speed_ms >= 0.0)
    for x, v in zip(tr.position_m[::5], tr.speed_ms[::5]):
        assert v <= _limit_under_train(case.line, case.train.length_m, x) + 1e-6
    assert tr.summary["limit_excess_ms"] == 0.0
    # stops at the platform within 0.5 m (the simulator's last landing can leave ~1e-6 m/s)
    assert tr.reached and tr.stop_error_m <= 0.5 and tr.speed_ms[-1] < 1e-3
    # work balance: traction - braking - resistance = change of kinetic energy (zero: rest to rest)
    s = tr.summary
    balance = s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"]
    assert abs(balance) <= 1e-6 * s["traction_work_j"]


@pytest.mark.parametrize("controller", CONTROLLERS, ids=lambda c: c.name)
def test_every_controller_stops_and_respects_limits(yizhuang, yizhuang_varied, controller):
    tr = track(yizhuang, yizhuang_varied, controller)
    _check_physics(yizhuang, tr)
    assert tr.summary["max_abs_accel_ms2"] <= 1.0 + 1e-6  # seed 000 caps |a| at 1 m/s^2


@settings(max_examples=12, deadline=None)
@given(codes_kmh=st.lists(st.floats(20.0, 80.0), min_size=8, max_size=8),
       which=st.integers(0, len(CONTROLLERS) - 1), period_s=st.sampled_from([0.1, 0.2, 0.5, 1.0]))
def test_random_references_obey_physics(yizhuang, yizhuang_sim, codes_kmh, which, period_s):
    bounds = gradient_limit_partition(yizhuang.line)
    ref = yizhuang_sim.run(speed_code_programs(bounds, np.array(codes_kmh) / 3.6)[0])
    _check_physics(yizhuang, track(yizhuang, ref, CONTROLLERS[which], control_period_s=period_s))


def test_energy_terms_from_the_trace(yizhuang, yizhuang_varied):
    """Resistance work recomputed from the trace, and the energy breakdown of the summary."""
    tr = track(yizhuang, yizhuang_varied, PID())
    a, b, c = yizhuang.train.resistance.coefficients_si(yizhuang.train.mass_kg)
    v_mid = 0.5 * (tr.speed_ms[1:] + tr.speed_ms[:-1])
    davis = np.sum((a + b * v_mid + c * v_mid**2) * np.diff(tr.position_m))
    assert tr.summary["davis_work_j"] == pytest.approx(davis, rel=2e-3)
    traction = np.sum(np.clip(tr.force_n[:-1], 0.0, None) * np.diff(tr.position_m))
    assert tr.summary["traction_work_j"] == pytest.approx(traction, rel=1e-9)
    # yizhuang: efficiency 1, no regeneration, no auxiliaries -> net = traction work at the wheel
    assert tr.energy.net_kwh == pytest.approx(traction / 3.6e6, rel=1e-9)
    # time: the sum of 2 dx / (v0 + v1)
    dt = 2.0 * np.diff(tr.position_m) / (tr.speed_ms[1:] + tr.speed_ms[:-1])
    assert tr.running_time_s == pytest.approx(np.sum(dt), rel=1e-9)


def test_traction_then_braking_reference_is_reproduced_exactly():
    """No middle part: maximum traction, then the braking curve. Tracking is the reference, and
    every figure of the summary (efficiencies, regen caps and cut-off, auxiliaries) is the
    simulator's."""
    case = make_case(line={"length_m": 600.0, "gradients": [[0.0, 600.0, 0.0]],
                           "speed_limits": [[0.0, 600.0, 100.0]]},
                     train={"traction_efficiency": 0.9, "regen_efficiency": 0.8, "regen_min_speed_kmh": 10.0,
                            "aux_power_kw": 40.0, "braking": {"max_force_kn": 100.0, "regen_max_force_kn": 60.0}})
    sim = Simulator(case)
    ref = sim.flat_out()
    assert ref.speed_ms.max() < 100 / 3.6 - 1.0  # never reaches the limit: traction, then braking
    assert set(np.unique(ref.regime)) == {REGIME_TRACTION, REGIME_BRAKE}
    assert ref.energy.regen_kwh > 0.0 and ref.energy.aux_kwh > 0.0
    for controller in CONTROLLERS:
        tr = track(case, ref, controller)
        for name in OUT_NAMES:
            assert tr.summary[name] == pytest.approx(ref.summary[name], rel=1e-12, abs=1e-12), name


def test_tracking_a_drivable_reference_reproduces_it(yizhuang, yizhuang_varied):
    ref = yizhuang_varied
    for controller in (PID(), FuzzyPID()):
        tr = track(yizhuang, ref, controller)
        v_ref = np.interp(tr.position_m, ref.position_m, ref.speed_ms)
        # the PID saturates at |e| = 1 / kp = 2 km/h; a maximum-traction reference can open a
        # slightly larger lag
        assert np.max(np.abs(tr.speed_ms - v_ref)) * 3.6 < 3.0
        assert tr.energy.net_kwh == pytest.approx(ref.energy.net_kwh, rel=0.03)
        assert tr.running_time_s == pytest.approx(ref.running_time_s, rel=0.005)


def _steady_cruise_cells(ref, tr):
    """Tracked nodes where the reference holds a constant speed (cruise) for at least 200 m."""
    cruise = (ref.regime[:-1] == REGIME_CRUISE) & (np.abs(np.diff(ref.speed_ms)) < 1e-9)
    cells = np.zeros(tr.position_m.shape[0], dtype=bool)
    k = 0
    while k < cruise.shape[0]:
        if cruise[k]:
            j = k
            while j < cruise.shape[0] and cruise[j]:
                j += 1
            if ref.position_m[j] - ref.position_m[k] >= 200.0:
                cells |= (tr.position_m >= ref.position_m[k] + 50.0) & (tr.position_m < ref.position_m[j])
            k = j
        k += 1
    return cells


@pytest.mark.parametrize("a_kmh, b_kmh", [(2.0, 3.0), (2.0, 5.0), (0.5, 4.0)])
def test_hysteresis_band_in_cruise(yizhuang, yizhuang_cruise, a_kmh, b_kmh):
    period = 0.2
    ref = yizhuang_cruise
    tr = track(yizhuang, ref, Hysteresis(a_kmh, b_kmh), control_period_s=period)
    cells = _steady_cruise_cells(ref, tr)
    assert cells.sum() > 500
    e_kmh = (np.interp(tr.position_m, ref.position_m, ref.speed_ms) - tr.speed_ms) * 3.6
    # a command lasts one control period (plus one cell): the speed can move by at most
    # a_max * that time past a threshold before the controller reacts
    a_max = (yizhuang.train.traction.force_kn(0.0) * 1000.0) / yizhuang.train.effective_mass_kg
    slack_kmh = min(a_max, 1.0) * (period + 0.1) * 3.6
    assert np.all(e_kmh[cells] >= a_kmh - slack_kmh)
    assert np.all(e_kmh[cells] <= b_kmh + slack_kmh)
    # the regimes of fig. 5-2: traction when more than B below, coasting when within A
    cell_e = e_kmh[:-1][cells[:-1]]
    cell_r = tr.regime[:-1][cells[:-1]]
    assert np.all(cell_r[cell_e > b_kmh + slack_kmh] == REGIME_TRACTION)
    assert np.all(cell_r[cell_e < a_kmh - slack_kmh] == REGIME_COAST)
    # and both happen: the band is used, not skipped
    assert (cell_r == REGIME_TRACTION).any() and (cell_r == REGIME_COAST).any()


def test_commands_are_held_for_a_control_period(yizhuang, yizhuang_cruise):
    period = 2.0
    tr = track(yizhuang, yizhuang_cruise, Hysteresis(2.0, 3.0), control_period_s=period)
    cells = _steady_cruise_cells(yizhuang_cruise, tr)[:-1]
    commanded = np.isin(tr.regime[:-1], (REGIME_TRACTION, REGIME_COAST))  # not the envelope's braking
    switches = np.flatnonzero(cells[1:] & cells[:-1] & commanded[1:] & commanded[:-1]
                              & (tr.regime[1:-1] != tr.regime[:-2])) + 1
    assert switches.size >= 4
    cell_time = np.max(np.diff(tr.time_s)[cells])
    assert np.all(np.diff(tr.time_s[switches]) >= period - cell_time - 1e-9)


def test_larger_b_costs_less_energy_and_more_time(yizhuang, yizhuang_sim):
    """Seed 000 5.4: with A fixed, a larger B coasts more. Per reference the stop phase can start
    at any point of a hysteresis cycle, so the energy is compared on average over cruise speeds;
    the running time grows for each one."""
    energy = {3.0: [], 6.0: []}
    for cruise_kmh in (60.0, 63.0, 66.0, 69.0):
        ref = cruise_reference(yizhuang_sim, cruise_kmh)
        runs = {b: track(yizhuang, ref, Hysteresis(2.0, b)) for b in energy}
        assert runs[6.0].running_time_s > runs[3.0].running_time_s
        for b, tr in runs.items():
            energy[b].append(tr.energy.net_kwh)
    assert np.mean(energy[6.0]) < np.mean(energy[3.0])


def test_overspeed_braking_on_a_descent():
    """A coasting train gains speed on a 30 permille descent; the controller brakes it back."""
    case = make_case(train={"resistance": {"a": 1.0, "b": 0.0, "c": 0.0, "unit": "kN", "speed_unit": "ms"}},
                     line={"length_m": 3000.0, "gradients": [[0.0, 800.0, 0.0], [800.0, 2200.0, -30.0],
                                                             [2200.0, 3000.0, 0.0]],
                           "speed_limits": [[0.0, 3000.0, 100.0]]})
    sim = Simulator(case)
    ref = sim.run(switching_programs([600.0], ("traction", "hold"), 3000.0)[0])
    tr = track(case, ref, Hysteresis(2.0, 3.0, overspeed_kmh=2.0))
    _check_physics(case, tr)
    on_descent = (tr.position_m > 1000.0) & (tr.position_m < 2100.0)
    v_ref = np.interp(tr.position_m, ref.position_m, ref.speed_ms)
    assert np.max((tr.speed_ms - v_ref)[on_descent]) * 3.6 < 2.0 + 1.0
    assert np.any(tr.force_n[:-1][on_descent[:-1]] < 0.0)


def test_neutral_sections_are_respected():
    case = make_case(line={"length_m": 3000.0, "gradients": [[0.0, 3000.0, 0.0]],
                           "speed_limits": [[0.0, 3000.0, 100.0]], "neutral_sections": [[1200.0, 1500.0]]},
                     train={"resistance": {"a": 2.0, "b": 0.0, "c": 0.0, "unit": "kN", "speed_unit": "ms"}})
    sim = Simulator(case)
    ref = cruise_reference(sim, 70.0)
    for controller in CONTROLLERS:
        tr = track(case, ref, controller)
        _check_physics(case, tr)
        assert tr.summary["neutral_traction_j"] == 0.0


def test_batch_equals_single_runs(yizhuang):
    tracker = Tracker(yizhuang, FuzzyPID(), control_period_s=0.3)
    bounds = gradient_limit_partition(yizhuang.line)
    rng = np.random.default_rng(5)
    programs = speed_code_programs(bounds, rng.uniform(30 / 3.6, 80 / 3.6, size=(6, 8)))
    batch = tracker.run_batch(programs)
    for j in (0, 3, 5):
        single = tracker.run_program(programs[j])
        for i, name in enumerate(OUT_NAMES):
            assert batch[j, i] == single.summary[name], name


def test_other_reference_grids(yizhuang, yizhuang_varied):
    """A reference on a coarser grid than the tracker's is interpolated, not misread."""
    coarse_ref = Simulator(yizhuang, dx_m=5.0).run(
        speed_code_programs(gradient_limit_partition(yizhuang.line),
                            np.array([55.0, 70.0, 72.0, 60.0, 75.0, 66.0, 50.0, 55.0]) / 3.6)[0])
    fine = track(yizhuang, yizhuang_varied, PID())
    coarse = track(yizhuang, coarse_ref, PID())
    _check_physics(yizhuang, coarse)
    assert coarse.energy.net_kwh == pytest.approx(fine.energy.net_kwh, rel=0.01)
    assert coarse.running_time_s == pytest.approx(fine.running_time_s, rel=0.002)
