"""The running-resistance estimate (``pymoo_rail.control.estimation``) and the speed filter before the trackers."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pymoo_rail.cases import load_case
from pymoo_rail.control.estimation import ResistanceEstimator, RunMeasurements, estimate_resistance
from pymoo_rail.control.policy import resistance_scaled, run_trace
from pymoo_rail.model.errors import FieldError
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.drivers import flat_out_program


@pytest.fixture(scope="module")
def metro():
    return load_case("metro-a")


def sampled(run, period_s, noise_ms=None):
    """The measurements of a simulator run at ``period_s`` instants (exact, or with ``noise_ms`` added in turn)."""
    x, v, t, f = run.position_m, run.speed_ms, run.time_s, run.force_n
    work = np.concatenate([[0.0], np.cumsum(f[:-1] * np.diff(x))])
    instants = np.append(np.arange(t[0], t[-1], period_s), t[-1])
    speed = np.interp(instants, t, v)
    if noise_ms is not None:
        speed = speed + noise_ms[: instants.shape[0]]
        speed[0] = 0.0
    return RunMeasurements(instants, np.interp(instants, t, x), speed, np.interp(instants, t, work))


@pytest.mark.parametrize("factor", [0.9, 1.0, 1.15])
def test_the_estimate_converges_on_the_true_factor_of_an_exact_run(metro, factor):
    # the real train's run is the simulator's own integration of the work balance the estimator
    # inverts: with exact speeds the factor comes back to the discretisation of the sum of W0 dx
    nominal = Simulator(metro).model
    real = resistance_scaled(nominal, factor)
    run = run_trace(real, flat_out_program(float(real.position_m[-1])))
    estimate, sd = estimate_resistance(nominal, sampled(run, 0.2), speed_sd_ms=0.0)
    assert estimate == pytest.approx(factor, abs=2e-3)
    assert sd < 1e-3


def test_sensor_noise_is_averaged_out_over_the_run(metro):
    nominal = Simulator(metro).model
    real = resistance_scaled(nominal, 1.12)
    run = run_trace(real, flat_out_program(float(real.position_m[-1])))
    sd_ms = 0.5 / 3.6
    noise = np.random.default_rng(3).normal(0.0, sd_ms, 4096)
    half = run.position_m <= 0.5 * run.position_m[-1]
    first = run.__class__(**{**run.__dict__, **{k: getattr(run, k)[half] for k in (
        "position_m", "speed_ms", "time_s", "accel_ms2", "force_n", "regime", "limit_ms")}})
    early, early_sd = estimate_resistance(nominal, sampled(first, 0.2, noise), sd_ms)
    late, late_sd = estimate_resistance(nominal, sampled(run, 0.2, noise), sd_ms)
    assert late_sd < early_sd < 0.1  # more of the run, more certain
    assert abs(late - 1.12) < 3.0 * late_sd + 5e-3
    assert abs(early - 1.12) < 3.0 * early_sd + 5e-3


def test_without_measurements_the_estimate_is_the_prior(metro):
    nominal = Simulator(metro).model
    one = RunMeasurements(np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1))
    assert estimate_resistance(nominal, one, 0.1, prior_sd=0.07) == (1.0, 0.07)


def test_the_factor_in_use_moves_in_steps_beyond_the_band(metro):
    nominal = Simulator(metro).model
    run = run_trace(resistance_scaled(nominal, 1.13), flat_out_program(float(nominal.position_m[-1])))
    estimator = ResistanceEstimator(step_factor=0.05)
    assert estimator.update(nominal, sampled(run, 0.2)) == pytest.approx(1.15)  # 1.13 rounded to the step
    exact = ResistanceEstimator(step_factor=0.05, factor=1.1)
    assert exact.update(nominal, sampled(run, 0.2)) == 1.1  # within a step of the factor in use: kept
    assert exact.history[-1][1] == pytest.approx(1.13, abs=2e-3)


def test_the_replanning_controller_learns_the_worlds_resistance(metro):
    from pymoo_rail.control import LoopDisturbance, OptimalControls, OptimalPolicy, closed_loop

    policy = OptimalPolicy(metro, 80.0)
    controller = OptimalControls(policy, 10.0)
    world = LoopDisturbance(resistance_factor=1.16, mass_factor=1.05, speed_noise_kmh=0.3, noise_seed=4)
    run = closed_loop(metro, controller, world, planned_time_s=80.0)
    assert run.summary["reached"] == 1.0
    assert controller.estimator.history[-1][1] == pytest.approx(1.16, abs=0.03)
    assert controller.estimator.factor == pytest.approx(1.16, abs=0.03)


def test_bad_measurements_and_settings_name_the_field(metro):
    with pytest.raises(FieldError, match=r"'measured.speed_ms\[2\]' = nan"):
        RunMeasurements(np.arange(3.0), np.arange(3.0), np.array([0.0, 1.0, np.nan]), np.zeros(3))
    with pytest.raises(FieldError, match="'measured.position_m'"):
        RunMeasurements(np.arange(3.0), np.arange(2.0), np.zeros(3), np.zeros(3))
    with pytest.raises(FieldError, match="'prior_sd' = 0"):
        ResistanceEstimator(prior_sd=0)
    with pytest.raises(FieldError, match="'step_factor' = -0.1"):
        ResistanceEstimator(step_factor=-0.1)
    from pymoo_rail.control import OptimalPolicy

    with pytest.raises(FieldError, match="'resistance_factor' = -1"):
        OptimalPolicy(metro, 80.0).replan(300.0, 15.0, 25.0, resistance_factor=-1)


@settings(max_examples=25, deadline=None)
@given(st.one_of(st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not 0 < x <= 1),
                 st.text(max_size=3), st.booleans()))
def test_a_filter_gain_outside_0_1_is_refused_by_name(alpha):
    from pymoo_rail.control.controllers import SpeedFilter

    with pytest.raises(FieldError, match="speed_filter.alpha"):
        SpeedFilter(alpha=alpha)


# ---------------------------------------------------------------- the speed filter
def filtered(values_true, values_meas, params, dt_s=0.2):
    from pymoo_rail.control import kernel as ck

    carry = np.zeros(ck.N_CARRY)
    return np.array([ck.filter_speed(carry, m, v, dt_s, params) for v, m in zip(values_true, values_meas)])


def test_the_filter_passes_the_reading_through_when_told():
    from pymoo_rail.control.controllers import NO_SPEED_FILTER

    meas = np.random.default_rng(1).normal(10.0, 0.2, 50)
    np.testing.assert_array_equal(filtered(np.full(50, 10.0), meas, NO_SPEED_FILTER.params()), meas)


@pytest.mark.parametrize("alpha", [0.1, 0.3])
def test_the_accelerometer_aided_filter_has_no_lag_and_leaves_its_share_of_the_noise(alpha):
    from pymoo_rail.control.controllers import SpeedFilter

    n = 20000
    true = 5.0 + 0.4 * 0.2 * np.arange(n) % 30.0  # ramps (and drops) of 0.4 m/s^2: a lagging filter trails them
    noise = np.random.default_rng(2).normal(0.0, 0.15, n)
    error = filtered(true, true + noise, SpeedFilter(alpha=alpha).params())[200:] - true[200:]
    assert abs(error.mean()) < 0.01
    assert error.std() == pytest.approx(0.15 * np.sqrt(alpha / (2.0 - alpha)), rel=0.05)


def test_the_alpha_beta_filter_follows_a_ramp_without_a_steady_error():
    from pymoo_rail.control.controllers import SpeedFilter

    true = 0.3 * 0.2 * np.arange(400)  # 0.3 m/s^2 from standstill
    est = filtered(true, true, SpeedFilter(accelerometer=False).params())
    assert abs(est[-1] - true[-1]) < 1e-3  # tracks the ramp in the end
    assert est[20] < true[20] - 0.05  # but lags it at first: it must learn the acceleration


def test_the_filter_saves_the_pid_the_energy_the_sensor_noise_costs():
    from pymoo_rail.control import PID, CurveTracking, LoopDisturbance, OptimalPolicy, closed_loop

    case = load_case("yizhuang")
    policy = OptimalPolicy(case, 150.0)
    world = LoopDisturbance(speed_noise_kmh=0.5, noise_seed=11)
    energy = {}
    for label, speed_filter in (("raw", None), ("filtered", "default"), ("quiet", None)):
        kwargs = {} if speed_filter == "default" else {"speed_filter": None}
        run = closed_loop(case, CurveTracking(policy.plan, PID(), **kwargs),
                          LoopDisturbance() if label == "quiet" else world, planned_time_s=150.0)
        energy[label] = run.summary["net_kwh"]
    # the noise costs the unfiltered PID energy; the filter wins most of it back
    assert energy["raw"] > energy["quiet"] * 1.03
    assert energy["filtered"] - energy["quiet"] < 0.5 * (energy["raw"] - energy["quiet"])
