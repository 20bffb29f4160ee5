"""ATO tracking layer: controllers that follow a recommended speed-distance curve, and driving in the loop.

The tracking controllers (``Hysteresis``, ``PID``, ``FuzzyPID``, ``track``) follow a fixed curve;
``OptimalPolicy`` re-plans the optimal rest of the run from any state, ``closed_loop`` drives a
disturbed train with a tracking, re-planning or advised driver, ``AdvisedDriving`` turns the
policy into driver advice (``docs/control.md``).

>>> from pymoo_rail.cases import load_case
>>> from pymoo_rail.sim import Simulator
>>> from pymoo_rail.control import Hysteresis, track
>>> case = load_case("yizhuang")
>>> ideal = Simulator(case).flat_out()
>>> tracked = track(case, ideal, Hysteresis(2, 4))
>>> tracked.stop_error_m < 0.5
True
"""

from pymoo_rail.control.controllers import (
    CLASSIC_RULES,
    PID,
    SYMMETRIC_RULES,
    TERMS,
    Controller,
    FuzzyPID,
    Hysteresis,
    make_controller,
    symmetric_rules,
)
from pymoo_rail.control.tracking import DEFAULT_CONTROL_PERIOD_S, Tracker, track, tracked_summaries
from pymoo_rail.control.comparison import TRACKING_METRICS, compare_tracking, tracking_metrics
from pymoo_rail.control.policy import OptimalPolicy, SpeedRestriction
from pymoo_rail.control.disturbances import (  # noqa: E402 (needs Tracker)
    DEFAULT_RANGES,
    Disturbance,
    disturbed_tracker,
    draw_disturbances,
    track_disturbed,
)
from pymoo_rail.control.closed_loop import (
    CurveTracking,
    LoopController,
    LoopDisturbance,
    LoopState,
    OptimalControls,
    Recovery,
    Replanning,
    closed_loop,
)

from pymoo_rail.control.advice import Advice, AdvisedDriving, advice_frame, advice_from_run

__all__ = ["Hysteresis", "PID", "FuzzyPID", "Controller", "CLASSIC_RULES", "SYMMETRIC_RULES",
           "symmetric_rules", "make_controller", "TERMS", "Tracker", "track",
           "tracked_summaries", "compare_tracking", "tracking_metrics", "TRACKING_METRICS", "DEFAULT_CONTROL_PERIOD_S", "Disturbance", "draw_disturbances",
           "disturbed_tracker", "track_disturbed", "DEFAULT_RANGES", "OptimalPolicy", "SpeedRestriction",
           "closed_loop", "LoopController", "LoopDisturbance", "LoopState", "CurveTracking", "Replanning",
           "Recovery", "OptimalControls", "Advice", "AdvisedDriving", "advice_from_run", "advice_frame"]
