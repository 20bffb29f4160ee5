"""Runs with closed-form answers: constant force on flat track, coasting against Davis resistance."""

import math

import numpy as np
import pytest

from pymoo_rail.sim import Simulator, switching_programs
from tests.conftest import make_case


def test_constant_force_from_rest():
    # F = 100 kN on 100 t with gamma 0.1, no resistance: v^2 = 2 F x / (m (1 + gamma))
    case = make_case(train={"rotary_factor": 0.1, "max_speed_kmh": 300.0},
                     line={"speed_limits": [[0.0, 2000.0, 300.0]]})
    sim = Simulator(case, dx_m=1.0)
    tr = sim.run(switching_programs([800.0], ("traction", "brake"), 2000.0)[0])
    m_eff = 100_000.0 * 1.1
    idx = np.searchsorted(tr.position_m, 600.0)
    assert tr.position_m[idx] == pytest.approx(600.0)
    assert tr.speed_ms[idx] == pytest.approx(math.sqrt(2 * 100_000.0 * 600.0 / m_eff), rel=1e-12)
    assert tr.time_s[idx] == pytest.approx(math.sqrt(2 * 600.0 * m_eff / 100_000.0), rel=1e-12)
    # traction work = F x over the traction part; braking with the same force takes as long again
    assert tr.summary["traction_work_j"] == pytest.approx(100_000.0 * 800.0, rel=1e-12)
    assert not tr.reached
    assert tr.summary["stop_position_m"] == pytest.approx(1600.0, abs=1e-6)
    assert tr.running_time_s == pytest.approx(2 * math.sqrt(2 * 800.0 * m_eff / 100_000.0), rel=1e-9)


def test_braking_envelope_takes_over_at_the_latest_moment():
    # full traction everywhere: with equal traction and braking forces and no resistance the
    # train accelerates over half the line and brakes over the other half
    case = make_case(train={"max_speed_kmh": 300.0}, line={"speed_limits": [[0.0, 2000.0, 300.0]]})
    tr = Simulator(case, dx_m=1.0).flat_out()
    assert tr.reached and tr.stop_error_m < 1e-9
    assert tr.summary["traction_work_j"] == pytest.approx(100_000.0 * 1000.0, rel=1e-3)
    assert tr.speed_ms.max() == pytest.approx(math.sqrt(2 * 1.0 * 1000.0), rel=1e-3)


def test_coasting_against_davis_resistance():
    # a + c v^2 (b = 0): coasting from v0 stops after m_eff / (2 c) ln(1 + c v0^2 / a)
    a_n, c_ns2 = 2000.0, 8.0
    case = make_case(train={"resistance": {"a": a_n / 1000.0, "b": 0.0, "c": c_ns2 / 1000.0,
                                           "unit": "kN", "speed_unit": "ms"},
                            "max_speed_kmh": 200.0},
                     line={"length_m": 30000.0, "gradients": [[0.0, 30000.0, 0.0]],
                           "speed_limits": [[0.0, 30000.0, 200.0]]})
    sim = Simulator(case, dx_m=1.0)
    tr = sim.run(switching_programs([600.0], ("traction", "coast"), 30000.0)[0])
    assert not tr.reached  # it runs out of speed before the platform
    start = np.searchsorted(tr.position_m, 600.0)
    v0 = tr.speed_ms[start]
    m_eff = case.train.effective_mass_kg
    expected = 600.0 + m_eff / (2.0 * c_ns2) * math.log(1.0 + c_ns2 * v0**2 / a_n)
    assert tr.summary["stop_position_m"] == pytest.approx(expected, rel=1e-4)
    # time to stop: m_eff / sqrt(a c) * atan(v0 sqrt(c / a))
    t_expected = tr.time_s[start] + m_eff / math.sqrt(a_n * c_ns2) * math.atan(v0 * math.sqrt(c_ns2 / a_n))
    assert tr.running_time_s == pytest.approx(t_expected, rel=1e-3)
    assert tr.stop_error_m == pytest.approx(30000.0 - expected, rel=1e-3)
    assert np.all(np.isfinite(tr.speed_ms))


def test_power_limited_top_speed():
    # with a power cap P and resistance c v^2 the balancing speed is (P / c)^(1/3)
    p_w, c = 2.0e6, 20.0
    case = make_case(train={"traction": {"max_force_kn": 200.0, "max_power_kw": p_w / 1000.0},
                            "resistance": {"a": 0.0, "b": 0.0, "c": c / 1000.0, "unit": "kN", "speed_unit": "ms"},
                            "max_speed_kmh": 400.0},
                     line={"length_m": 30000.0, "gradients": [[0.0, 30000.0, 0.0]],
                           "speed_limits": [[0.0, 30000.0, 400.0]]})
    tr = Simulator(case, dx_m=5.0).run(switching_programs([25000.0], ("traction", "brake"), 30000.0)[0])
    idx = np.searchsorted(tr.position_m, 24000.0)
    assert tr.speed_ms[idx] == pytest.approx((p_w / c) ** (1 / 3), rel=1e-3)
