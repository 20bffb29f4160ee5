"""Physics of simulated runs on the built-in line: conservation, limits, stopping, caps."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pymoo_rail.model import GRAVITY_MS2
from pymoo_rail.sim import (
    Simulator,
    equal_partition,
    gradient_limit_partition,
    speed_code_programs,
    switching_programs,
)
from pymoo_rail.sim.kernel import OUT_NAMES
from tests.conftest import make_case


def _limit_under_train(line, train_length_m, x):
    """Lowest limit anywhere under a train whose head is at x (independent of the grid code)."""
    lo = max(0.0, x - train_length_m)
    return min(v for s, e, v in line.speed_limits if s <= x and e > lo) / 3.6


def _check_run(case, tr, tol_ms=1e-6):
    # never above any limit under the train
    for x, v in zip(tr.position_m[::7], tr.speed_ms[::7]):
        assert v <= _limit_under_train(case.line, case.train.length_m, x) + tol_ms
    assert np.all(np.isfinite(tr.speed_ms)) and np.all(tr.speed_ms >= 0)
    s = tr.summary
    # work balance: traction - braking = kinetic + resistance + potential
    kinetic = 0.5 * case.train.effective_mass_kg * tr.speed_ms[-1] ** 2
    balance = s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] - kinetic
    assert abs(balance) <= 1e-6 * s["traction_work_j"]


def _davis_work_from_trace(case, tr):
    a, b, c = case.train.resistance.coefficients_si(case.train.mass_kg)
    v_mid = 0.5 * (tr.speed_ms[1:] + tr.speed_ms[:-1])
    return np.sum((a + b * v_mid + c * v_mid**2) * np.diff(tr.position_m))


def _mean_altitude(line, head, length):
    s = np.linspace(head - length, head, 4001)
    return np.trapezoid(line.altitude_m(np.clip(s, 0, line.length_m)), s) / length


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(20.0, 80.0), min_size=8, max_size=8))
def test_speed_codes_obey_physics(yizhuang, yizhuang_sim, codes_kmh):
    bounds = gradient_limit_partition(yizhuang.line)
    tr = yizhuang_sim.run(speed_code_programs(bounds, np.array(codes_kmh) / 3.6)[0])
    assert tr.reached and tr.stop_error_m < 1e-6 and tr.speed_ms[-1] == 0.0
    _check_run(yizhuang, tr)
    # independent checks of two terms of the balance
    assert tr.summary["davis_work_j"] == pytest.approx(_davis_work_from_trace(yizhuang, tr), rel=2e-3)
    rise = _mean_altitude(yizhuang.line, 2265.0, 140.0) - _mean_altitude(yizhuang.line, 0.0, 140.0)
    assert tr.summary["grade_work_j"] == pytest.approx(yizhuang.train.mass_kg * GRAVITY_MS2 * rise, rel=1e-4)
    # caps of seed 000 4.3.1: |a| <= 1 m/s^2
    assert tr.summary["max_abs_accel_ms2"] <= 1.0 + 1e-6


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(0.0, 2265.0), min_size=3, max_size=3))
def test_switching_points_obey_physics(yizhuang, yizhuang_sim, points):
    tr = yizhuang_sim.run(switching_programs(points, ("traction", "hold", "coast", "brake"), 2265.0)[0])
    _check_run(yizhuang, tr)
    if tr.reached:
        assert tr.stop_error_m < 1e-6
    else:  # braked or coasted to a stop short of the platform: the error says by how much
        assert tr.stop_error_m == pytest.approx(2265.0 - tr.summary["stop_position_m"])
        assert tr.stop_error_m > 0


def test_batch_equals_single_runs(yizhuang, yizhuang_sim):
    rng = np.random.default_rng(3)
    bounds = equal_partition(yizhuang.line, 10)
    codes = rng.uniform(5.0, 22.0, size=(16, 10))
    programs = speed_code_programs(bounds, codes)
    batch = yizhuang_sim.run_batch(programs)
    for j in (0, 7, 15):
        single = yizhuang_sim.run(programs[j])
        for i, name in enumerate(OUT_NAMES):
            assert batch[j, i] == single.summary[name]


def test_flat_out_is_fastest_and_stops(yizhuang_sim):
    fastest = yizhuang_sim.flat_out()
    assert fastest.reached and fastest.stop_error_m < 1e-6
    # seed 000: 150 s is a feasible timetable, so the flat-out run must be faster
    assert fastest.running_time_s < 150.0
    bounds = gradient_limit_partition(yizhuang_sim.case.line)
    slower = yizhuang_sim.run(speed_code_programs(bounds, np.full(8, 70 / 3.6))[0])
    assert slower.running_time_s > fastest.running_time_s
    assert slower.energy.net_kwh < fastest.energy.net_kwh


def test_neutral_sections_have_no_traction():
    case = make_case(train={"max_speed_kmh": 300.0},
                     line={"neutral_sections": [[600.0, 900.0]], "speed_limits": [[0.0, 2000.0, 300.0]]})
    sim = Simulator(case, dx_m=1.0)
    tr = sim.run(switching_programs([1100.0], ("traction", "brake"), 2000.0)[0])
    inside = (tr.position_m >= 600.0) & (tr.position_m < 900.0)
    assert np.all(tr.force_n[inside] <= 0.0)
    assert tr.summary["neutral_traction_j"] == 0.0
    before = (tr.position_m > 100.0) & (tr.position_m < 590.0)
    assert np.all(tr.force_n[before] > 0.0)


def test_regenerative_braking_accounting():
    case = make_case(train={"regen_efficiency": 0.8, "traction_efficiency": 0.9, "aux_power_kw": 50.0,
                            "regen_min_speed_kmh": 10.0,
                            "braking": {"max_force_kn": 100.0, "regen_max_force_kn": 60.0}})
    sim = Simulator(case, dx_m=1.0)
    tr = sim.run(switching_programs([1000.0], ("traction", "brake"), 2000.0)[0])
    s = tr.summary
    assert s["electric_brake_work_j"] <= 0.6 * s["brake_work_j"] + 1e-6
    assert s["electric_brake_work_j"] > 0.5 * s["brake_work_j"]
    e = tr.energy
    assert e.traction_kwh == pytest.approx(s["traction_work_j"] / 0.9 / 3.6e6)
    assert e.regen_kwh == pytest.approx(0.8 * s["electric_brake_work_j"] / 3.6e6)
    assert e.aux_kwh == pytest.approx(50.0 * tr.running_time_s / 3600.0)
    assert e.net_kwh == pytest.approx(e.traction_kwh + e.aux_kwh - e.regen_kwh)


def test_no_regen_below_cutoff():
    case = make_case(train={"regen_efficiency": 1.0, "regen_min_speed_kmh": 500.0})
    tr = Simulator(case).run(switching_programs([1000.0], ("traction", "brake"), 2000.0)[0])
    assert tr.energy.regen_kwh == 0.0


def test_stall_is_reported_not_nan():
    # a 40 permille climb the train cannot take at 20 kN
    case = make_case(train={"traction": {"max_force_kn": 20.0}},
                     line={"gradients": [[0.0, 500.0, 0.0], [500.0, 2000.0, 40.0]]})
    tr = Simulator(case).flat_out()
    assert not tr.reached and 500.0 < tr.summary["stop_position_m"] < 2000.0
    assert np.isfinite(tr.running_time_s) and np.isfinite(tr.energy.net_kwh)


def _descent_case(descent_permille: float):
    """2 km flat, 2 km of descent, 1 km flat; Davis resistance and regeneration."""
    return make_case(
        allow_implausible=["gradient"],  # -120 permille: steeper than any adhesion line, on purpose
        train={"regen_efficiency": 0.8, "regen_min_speed_kmh": 5.0,
               "resistance": {"a": 2.0, "b": 0.0, "c": 0.0005, "unit": "kN", "speed_unit": "kmh"},
               "braking": {"max_force_kn": 100.0, "regen_max_force_kn": 60.0}},
        line={"length_m": 5000.0, "speed_limits": [[0.0, 5000.0, 100.0]],
              "gradients": [[0.0, 2000.0, 0.0], [2000.0, 4000.0, descent_permille], [4000.0, 5000.0, 0.0]]})


@pytest.mark.parametrize("descent_permille, holds", [(-20.0, True), (-120.0, False)])
def test_hold_brake_keeps_the_speed_down_a_descent_where_hold_runs_away(descent_permille, holds):
    # -120 permille pulls harder (1.18 m/s^2) than the brakes (1 m/s^2 at 100 t) can hold
    case = _descent_case(descent_permille)
    sim = Simulator(case, dx_m=1.0)
    regimes = ("traction", "coast", "hold", "brake")
    points = [180.0, 1500.0, 5000.0]  # hold to the end: the braking envelope stops it at the platform
    hold = sim.run(switching_programs(points, regimes, 5000.0)[0])
    brake_hold = sim.run(switching_programs(points, regimes[:2] + ("hold_brake", "brake"), 5000.0)[0])
    for tr in (hold, brake_hold):
        _check_run(case, tr)
        assert tr.reached and tr.stop_error_m < 1e-6
    entry = np.searchsorted(brake_hold.position_m, 1500.0)
    v_hold = brake_hold.speed_ms[entry]
    assert 10.0 < v_hold < 100 / 3.6 - 5.0  # the held speed is well under the limit
    # flat before the descent: both modes are the same run, node for node
    flat = brake_hold.position_m < 2000.0 - case.train.length_m
    np.testing.assert_array_equal(hold.speed_ms[flat], brake_hold.speed_ms[flat])
    down = (brake_hold.position_m > 2100.0) & (brake_hold.position_m < 3900.0)
    if holds:
        # partial braking holds the entry speed to rounding, with a braking force below the maximum
        np.testing.assert_allclose(brake_hold.speed_ms[down], v_hold, rtol=1e-9)
        force = brake_hold.force_n[down]
        assert np.all(force < 0.0) and np.all(-force < 100e3)
        assert brake_hold.energy.regen_kwh > 0.5  # the held descent regenerates
        # "hold" coasts instead: it runs up to the limit, where the braking envelope holds it
        assert hold.speed_ms[down].max() > 100 / 3.6 - 0.1
        assert brake_hold.running_time_s > hold.running_time_s
    else:
        # too steep: maximum braking, and the speed still rises until the limit's envelope
        assert np.any(brake_hold.force_n[down] == pytest.approx(-100e3))
        assert brake_hold.speed_ms[down].max() > v_hold + 1.0


def test_runs_side_by_side_equal_single_runs_when_one_stops_short(yizhuang_sim):
    """Batches run programs in pairs; a pair whose runs end at different cells (one brakes to a
    stop half way) and an odd batch give exactly the single runs' summaries, serial or threaded."""
    from pymoo_rail.sim import kernel as k

    length = yizhuang_sim.length_m
    reach = [[length, k.MODE_TOWARD, 60 / 3.6]]
    stop_short = [[600.0, k.MODE_TRACTION, 0.0], [length, k.MODE_BRAKE, 0.0]]
    coast = [[900.0, k.MODE_TRACTION, 0.0], [length, k.MODE_COAST, 0.0]]
    programs = np.array([np.array(p + p[-1:] * (2 - len(p)), dtype=float)
                         for p in (reach, stop_short, stop_short, reach, coast)])
    single = np.array([[yizhuang_sim.run(p).summary[name] for name in OUT_NAMES] for p in programs])
    assert single[1, k.OUT_REACHED] == 0.0 and single[0, k.OUT_REACHED] == 1.0
    for batch in (k.simulate_batch(yizhuang_sim.model, programs),
                  k.simulate_batch_serial(yizhuang_sim.model, programs),
                  yizhuang_sim.run_batch(programs)):
        np.testing.assert_array_equal(batch, single)
