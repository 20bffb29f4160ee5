"""The peak traction power of a run (``peak_traction_kw``) and the ``peak_power`` objective."""

import math

import numpy as np
import pytest

from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import Simulator, switching_programs
from tests.conftest import make_case

ETA = 0.85


def _powered_case(max_power_kw: float = 1000.0):
    # 100 kN up to 10 m/s, then 1 MW: level track, no resistance
    return make_case(train={"traction": {"max_force_kn": 100.0, "max_power_kw": max_power_kw},
                            "traction_efficiency": ETA, "max_speed_kmh": 300.0},
                     line={"length_m": 5000.0, "gradients": [[0.0, 5000.0, 0.0]],
                           "speed_limits": [[0.0, 5000.0, 300.0]]})


def test_flat_out_peak_is_the_power_cap_over_the_efficiency():
    tr = Simulator(_powered_case(), dx_m=1.0).flat_out()
    assert tr.speed_ms.max() > 20.0  # far into the power-capped range
    peak = tr.summary["peak_traction_kw"]
    # a cell's mean power F (v0 + v1) / 2 with F = P / v_half, v_half >= (v0 + v1) / 2: never above
    # the cap, below it by O(dv^2 / v^2) on a 1 m grid
    assert peak <= 1000.0 / ETA * (1 + 1e-12)
    assert peak == pytest.approx(1000.0 / ETA, rel=1e-4)


def test_peak_below_the_power_cap_is_force_times_speed():
    # 100 kN on 100 t: 1 m/s^2; traction over 20 m reaches sqrt(40) m/s < 10 m/s, where the force cap binds
    tr = Simulator(_powered_case(), dx_m=1.0).run(switching_programs([20.0], ("traction", "brake"), 5000.0)[0])
    mean_speed_last_cell = 0.5 * (math.sqrt(2 * 19.0) + math.sqrt(2 * 20.0))
    assert tr.summary["peak_traction_kw"] == pytest.approx(100.0 * mean_speed_last_cell / ETA, rel=1e-9)


def test_peak_equals_the_trace_and_energy_bounds_it(yizhuang, yizhuang_sim):
    tr = yizhuang_sim.flat_out()
    v = tr.speed_ms
    cell_power_kw = np.maximum(tr.force_n[:-1], 0.0) * 0.5 * (v[:-1] + v[1:]) / 1000.0
    eta = yizhuang.train.traction_efficiency
    assert tr.summary["peak_traction_kw"] == pytest.approx(cell_power_kw.max() / eta, rel=1e-12)
    # traction energy = integral of the power over time <= peak x running time
    assert tr.energy.traction_kwh <= tr.summary["peak_traction_kw"] * tr.running_time_s / 3600.0


def test_peak_power_objective_reads_the_kernel_column(yizhuang):
    p = SpeedProfileProblem(yizhuang, objectives=("energy", "peak_power"))
    X = np.random.default_rng(2).uniform(p.xl, p.xu, (6, p.n_var))
    F = p.evaluate(X, return_as_dictionary=True)["F"]
    peaks = [p.trajectory(x).summary["peak_traction_kw"] for x in X]
    np.testing.assert_array_equal(F[:, 1], peaks)
    # the weighted sum scales it by the flat-out run's peak (the objective table's default)
    weighted = SpeedProfileProblem(yizhuang, objectives=("energy", "peak_power"), weights=(1.0, 1.0))
    assert weighted.scales[1] == Simulator(yizhuang).flat_out().summary["peak_traction_kw"]
