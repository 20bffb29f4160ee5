"""The tracking layer with the exact solver's part-power runs (a varying traction efficiency map):
a controller tracks the optimum, a tracked batch takes its four-column program, and the optimal
policy re-plans with part-power rows."""

import numpy as np
import pytest

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.control import PID, OptimalPolicy, Tracker, track
from pymoo_rail.optimal import OptimalSolver
from tests.optimal.cases import level_case
from tests.optimal.test_part_power import DX_M, FALLING, RUNNING_TIME_S, _mapped

from .test_tracking import _check_physics


@pytest.fixture(scope="module")
def falling_case():
    return _mapped(level_case(), FALLING)


def test_a_part_power_optimum_is_tracked_with_the_map(falling_case):
    solver = OptimalSolver(falling_case, dx_m=DX_M, certify=False)
    reference = solver.profile(RUNNING_TIME_S)
    tracked = track(falling_case, reference, PID(), dx_m=DX_M)
    _check_physics(falling_case, tracked)
    assert tracked.summary["control_error_rms_kmh"] < 2.0
    # the tracked run is costed with the map, cell by cell
    x, v, f = tracked.position_m, tracked.speed_ms, tracked.force_n[:-1]
    d, vm_kmh = np.diff(x), 0.5 * (v[1:] + v[:-1]) * KMH_PER_MS
    electric = np.where(f > 0, f * d / FALLING.efficiency(vm_kmh, f / 1000.0), 0.0).sum()
    assert tracked.summary["traction_kwh"] * J_PER_KWH == pytest.approx(electric, rel=1e-9)
    # a batch of four-column programs (the optimum's) is tracked as its single run is
    program = solver.solve_price(reference.summary["lambda_w"]).program
    assert program.shape[1] == 4 and np.any(program[:, 3] < 1.0)
    tracker = Tracker(falling_case, PID(), dx_m=DX_M)
    single = tracker.run_program(program)
    batch = tracker.run_batch(program[None])
    assert batch[0, 0] == pytest.approx(single.summary[next(iter(single.summary))])
    with pytest.raises(ValueError, match="rows, 4"):
        tracker.run_batch(np.zeros((1, 2, 5)))


def test_the_policy_replans_with_part_power(falling_case):
    policy = OptimalPolicy(falling_case, RUNNING_TIME_S, dx_m=DX_M, n_speeds=100)
    rest = policy.replan(400.0, 8.0, 45.0)  # slow: it accelerates again
    assert abs(rest.running_time_s - RUNNING_TIME_S) < 0.5
    shares = policy.last_program[:, 3]
    assert policy.last_program.shape[1] == 4 and np.any((shares > 0.0) & (shares < 1.0))
