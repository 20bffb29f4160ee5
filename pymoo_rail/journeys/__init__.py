"""Whole-line journeys: consecutive sections, one train, and the energy-minimal split of the trip time.

A journey is a :class:`~pymoo_rail.model.Case` with one leg per stop-to-stop section; :class:`Journey`
is its view with stop names and track positions, and every function here takes either.

>>> from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
>>> from pymoo_rail.journeys import allocate_running_time, load_journey, section_fronts
>>> journey = load_journey(YIZHUANG_TRACK, train=BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)
>>> fronts = section_fronts(journey)                    # one convex energy-time front per section
>>> best = allocate_running_time(journey, journey.running_time_s(30 * 60), fronts=fronts)
>>> best.table[["label", "running_time_s", "energy_kwh"]]  # doctest: +SKIP
"""

from pymoo_rail.journeys.allocation import (
    DEFAULT_FRONT_SOURCE,
    Allocation,
    allocate_on_fronts,
    allocate_running_time,
    marginal_slopes,
    section_fronts,
    supplement_split,
)
from pymoo_rail.journeys.fronts import (
    check_front,
    convex_front,
    front_energy,
    front_slopes,
    strategy_front,
    strategy_programs,
)
from pymoo_rail.journeys.journey import Journey, as_journey, join_lines
from pymoo_rail.journeys.timing import (
    TimedJourney,
    TimedRun,
    TimingError,
    TimingPoint,
    solve_timed_journey,
)
from pymoo_rail.journeys.formats import (
    JOURNEY_FORMATS,
    journey_from_ttobench,
    journey_to_ttobench,
    load_journey,
    read_timing_points,
    timed_journey_from_toml,
    timed_journey_from_ttobench,
)
from pymoo_rail.journeys.timed_problem import TimedSectionProblem
from pymoo_rail.journeys.problem import BudgetRepair, RunningTimeAllocationProblem, project_to_budget

__all__ = ["Journey", "as_journey", "join_lines", "Allocation", "allocate_running_time", "allocate_on_fronts", "supplement_split",
           "section_fronts", "marginal_slopes", "strategy_front", "strategy_programs", "convex_front",
           "check_front", "front_energy", "front_slopes", "RunningTimeAllocationProblem", "BudgetRepair",
           "project_to_budget", "DEFAULT_FRONT_SOURCE", "TimingPoint", "TimedJourney", "TimedRun", "TimingError",
           "read_timing_points", "timed_journey_from_ttobench", "timed_journey_from_toml", "solve_timed_journey", "TimedSectionProblem",
           "load_journey", "journey_from_ttobench", "journey_to_ttobench", "JOURNEY_FORMATS"]
