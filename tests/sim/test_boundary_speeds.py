"""Runs that start and end at a non-zero speed (run.initial_speed_kmh / run.final_speed_kmh)."""

import numpy as np
import pytest

from pymoo_rail.model import CaseError, InfeasibleCaseError, case_from_dict, case_to_dict
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs, switching_programs
from tests.conftest import make_case, make_case_dict


def _moving_case(v0_kmh=36.0, v1_kmh=18.0):
    return make_case(run={"planned_time_s": 100.0, "initial_speed_kmh": v0_kmh, "final_speed_kmh": v1_kmh},
                     train={"resistance": {"a": 1.0, "b": 0.05, "c": 0.01, "unit": "kN", "speed_unit": "ms"}})


def test_case_file_fields_are_kmh_and_the_case_holds_si():
    case = _moving_case(36.0, 18.0)
    assert case.initial_speed_ms == pytest.approx(10.0) and case.final_speed_ms == pytest.approx(5.0)
    back = case_from_dict(case_to_dict(case))
    assert back.initial_speed_ms == pytest.approx(10.0, rel=1e-15)
    assert back.final_speed_ms == pytest.approx(5.0, rel=1e-15)
    assert make_case().initial_speed_ms == 0.0 and make_case().final_speed_ms == 0.0


@pytest.mark.parametrize("field,value,reason", [("initial_speed_kmh", -1.0, ">= 0"),
                                                ("final_speed_kmh", "fast", "finite"),
                                                ("final_speed_kmh", float("nan"), "finite"),
                                                ("initial_speed_kmh", 120.0, "speed limit")])
def test_bad_boundary_speed_names_the_field(field, value, reason):
    data = make_case_dict(run={"planned_time_s": 100.0, field: value})
    with pytest.raises(CaseError, match=f"run.{field}.*{reason}"):
        case_from_dict(data)


def test_initial_speed_above_the_braking_envelope_is_infeasible():
    # 100 km/h at the start of a 2 km line whose limit drops to 20 km/h after 20 m
    case = make_case(run={"planned_time_s": 100.0, "initial_speed_kmh": 90.0},
                     line={"length_m": 2000.0, "gradients": [[0.0, 2000.0, 0.0]],
                           "speed_limits": [[0.0, 20.0, 100.0], [20.0, 2000.0, 20.0]]})
    with pytest.raises(InfeasibleCaseError, match="run.initial_speed_kmh"):
        Simulator(case)


@pytest.mark.parametrize("program", ["coast", "codes", "switching"])
def test_runs_start_and_end_at_the_boundary_speeds_with_energy_balance(program):
    case = _moving_case()
    sim = Simulator(case)
    if program == "coast":
        prog = np.array([[case.line.length_m, 3.0, 0.0]])  # coasting all the way from 36 km/h
    elif program == "codes":
        prog = speed_code_programs(gradient_limit_partition(case.line), np.array([20.0]))[0]
    else:
        prog = switching_programs(np.array([500.0, 1500.0]), ("traction", "hold", "coast"), case.line.length_m)[0]
    tr = sim.run(prog)
    assert tr.speed_ms[0] == pytest.approx(10.0)
    assert tr.reached
    s = tr.summary
    m_eff = case.train.effective_mass_kg
    kinetic = 0.5 * m_eff * (tr.speed_ms[-1] ** 2 - tr.speed_ms[0] ** 2)
    balance = s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] - kinetic
    assert abs(balance) <= 1e-6 * max(s["traction_work_j"], s["brake_work_j"], abs(kinetic))
    if program != "coast":  # fast enough to need braking at the end: lands on the final speed
        assert tr.speed_ms[-1] == pytest.approx(5.0, abs=1e-12)
        assert s["brake_work_j"] > 0.0
    assert sim.model.envelope_ms[-1] == pytest.approx(5.0)


def test_optimal_profile_honours_the_boundary_speeds():
    from pymoo_rail.optimal import OptimalSolver

    case = _moving_case()
    solver = OptimalSolver(case, n_speeds=60)
    tr = solver.profile(130.0)  # the solver's run is replayed in the simulator and checked against it
    assert tr.speed_ms[0] == pytest.approx(10.0) and tr.speed_ms[-1] == pytest.approx(5.0, abs=1e-9)
    assert abs(tr.running_time_s - 130.0) <= 0.5
