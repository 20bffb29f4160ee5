"""Closed-loop runs: segments equal one run, late departures recovered, restrictions kept, own controllers."""

import math

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, Hysteresis, OptimalPolicy, SpeedRestriction, track
from pymoo_rail.control.closed_loop import (
    CurveTracking,
    LoopDisturbance,
    LoopState,
    Recovery,
    Replanning,
    closed_loop,
)
from pymoo_rail.model.errors import FieldError

PLANNED_S = 80.0


@pytest.fixture(scope="module")
def metro():
    return load_case("metro-a")


@pytest.fixture(scope="module")
def policy(metro):
    return OptimalPolicy(metro, PLANNED_S)


@pytest.mark.parametrize("tracker", [PID(), Hysteresis(2, 4)])
def test_a_run_cut_at_decisions_is_the_run_in_one_piece(metro, policy, tracker):
    whole = closed_loop(metro, CurveTracking(policy.plan, tracker), planned_time_s=PLANNED_S)
    pieces = closed_loop(metro, CurveTracking(policy.plan, tracker, decide_every_s=3.0), planned_time_s=PLANNED_S)
    assert pieces.summary["n_decisions"] > 10
    np.testing.assert_allclose(pieces.speed_ms, whole.speed_ms, atol=1e-9)
    assert pieces.energy.net_kwh == pytest.approx(whole.energy.net_kwh, rel=1e-9)


def test_nominal_tracking_is_the_tracking_layer_run(metro, policy):
    loop = closed_loop(metro, CurveTracking(policy.plan, PID()), planned_time_s=PLANNED_S)
    direct = track(metro, policy.plan, PID())
    assert loop.energy.net_kwh == pytest.approx(direct.energy.net_kwh, rel=1e-9)
    assert loop.running_time_s == pytest.approx(direct.running_time_s, rel=1e-12)
    assert loop.summary["reached"] == 1.0 and loop.stop_error_m < 0.5


def test_replanning_recovers_a_late_departure_that_tracking_does_not(metro, policy):
    late = LoopDisturbance(departure_delay_s=4.0)
    tracked = closed_loop(metro, CurveTracking(policy.plan, PID()), late, planned_time_s=PLANNED_S)
    replanned = closed_loop(metro, Replanning(policy, PID(), 5.0), late, planned_time_s=PLANNED_S)
    recovered = closed_loop(metro, Recovery(policy.plan, metro, PID(), 5.0), late, planned_time_s=PLANNED_S)
    assert tracked.summary["lateness_s"] > 3.5
    assert abs(replanned.summary["lateness_s"]) <= 2.0
    assert recovered.summary["lateness_s"] < tracked.summary["lateness_s"] - 2.0
    assert replanned.time_s[0] == 4.0 and replanned.running_time_s == pytest.approx(replanned.time_s[-1] - 4.0)
    for run in (tracked, replanned, recovered):
        assert run.summary["reached"] == 1.0 and run.stop_error_m < 0.5


def test_an_announced_restriction_is_kept_and_replanned_for(metro, policy):
    restriction = SpeedRestriction(550.0, 650.0, 60.0)
    world = LoopDisturbance(restriction=restriction, announce_m=300.0)
    seen = []

    class Spy(Replanning):
        def reference(self, state):
            seen.append((state, super().reference(state)))
            return seen[-1][1]

    run = closed_loop(metro, Spy(policy, PID(), math.inf), world, planned_time_s=PLANNED_S)
    inside = (run.position_m >= 550.0) & (run.position_m < 650.0 + metro.train.length_m)
    assert run.speed_ms[inside].max() * 3.6 <= 60.0 + 1e-6
    assert len(run.summary["decision_points_m"]) == 2 and run.summary["decision_points_m"][1] >= 300.0
    assert abs(run.summary["lateness_s"]) <= 2.0


def test_a_users_own_controller_plugs_in(metro, policy):
    class SlowDown:
        name, tracker, decide_every_s = "own", PID(), math.inf

        def __init__(self):
            self.states = []

        def reference(self, state: LoopState):
            self.states.append(state)
            return policy.fastest(state.position_m, state.speed_ms, state.elapsed_s)

    own = SlowDown()
    run = closed_loop(metro, own, LoopDisturbance(mass_factor=1.1), planned_time_s=PLANNED_S)
    assert own.states[0].event == "departure" and own.states[0].mass_t == pytest.approx(metro.train.mass_t * 1.1)
    assert run.running_time_s < PLANNED_S - 5.0  # it followed the fastest run


@pytest.mark.parametrize("kwargs, field", [({"departure_delay_s": -1.0}, "departure_delay_s"),
                                           ({"resistance_factor": 0.0}, "resistance_factor"),
                                           ({"regen_factor": math.nan}, "regen_factor"),
                                           ({"restriction": (1, 2, 3)}, "restriction")])
def test_bad_disturbances(kwargs, field):
    with pytest.raises(FieldError, match=f"'{field}'"):
        LoopDisturbance(**kwargs)


def test_bad_decision_period(metro, policy):
    with pytest.raises(FieldError, match="'controller.decide_every_s' = 0.0"):
        closed_loop(metro, CurveTracking(policy.plan, PID(), decide_every_s=0.0))


def test_a_train_just_behind_a_tight_plan_is_not_driven_flat_out(metro):
    """metro-a at 75 s: the plan's last coast ends 0.05 s behind 75 s, and flat out saves little time."""
    from pymoo_rail.control.closed_loop import OptimalControls

    tight = OptimalPolicy(metro, 75.0)
    run = closed_loop(metro, OptimalControls(tight, 10.0), planned_time_s=75.0)
    # re-planning on the plan changes nothing; flat out from 879 m cost 0.40 kWh (2.3 %) more
    assert run.energy.net_kwh == pytest.approx(tight.plan.energy.net_kwh, rel=1e-3)
    assert abs(run.summary["lateness_s"]) <= 0.5


def test_the_optimal_controls_applied_directly_arrive_on_time(metro, policy):
    from pymoo_rail.control.closed_loop import OptimalControls

    nominal = closed_loop(metro, OptimalControls(policy, 10.0), planned_time_s=PLANNED_S)
    assert abs(nominal.summary["lateness_s"]) <= 0.5
    # nominal: re-planning on the plan changes nothing but the grid's rounding
    assert nominal.energy.net_kwh == pytest.approx(policy.plan.energy.net_kwh, rel=0.01)
    heavy_late = LoopDisturbance(departure_delay_s=3.0, mass_factor=1.1, resistance_factor=1.1)
    run = closed_loop(metro, OptimalControls(policy, 5.0), heavy_late, planned_time_s=PLANNED_S)
    assert abs(run.summary["lateness_s"]) <= 1.0 and run.summary["reached"] == 1.0


@pytest.mark.slow
def test_a_long_line_with_weak_adhesion_arrives_on_time():
    """48 km, a 10 % heavier train on 0.895 adhesion: planned on the nominal brakes, it arrived 4.2 s late."""
    from pymoo_rail.control.closed_loop import OptimalControls
    from pymoo_rail.control.study import draw_loop_disturbances, study_planned_time

    case = load_case("wuguang-crh3")
    planned = study_planned_time(case)  # 8 % above the minimum running time
    world = draw_loop_disturbances(case, 2, 1, planned)[1]
    assert world.adhesion_factor < 0.9 and world.mass_factor > 1.09 and world.departure_delay_s == 0.0
    run = closed_loop(case, OptimalControls(OptimalPolicy(case, planned), 10.0), world, planned_time_s=planned)
    assert run.summary["reached"] == 1.0
    assert abs(run.summary["lateness_s"]) <= 2.0
