"""Journeys with timing points: the TTOBench journey format, reachability and the exact solve."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from pymoo_rail.cases.ttobench import TTOBenchWarning, read_track
from pymoo_rail.journeys import (
    TimingError,
    read_timing_points,
    solve_timed_journey,
    timed_journey_from_ttobench,
)
from pymoo_rail.model import CaseError

RELEASE = Path(__file__).resolve().parents[1] / "data" / "ttobench"
JOURNEY = RELEASE / "journeys" / "CH_StGallen_Wil_Journey_01.json"
FIRST_PUBLISHED = RELEASE / "journeys" / "CH_StGallen_Wil_Journey_01_first_published.json"
TRACK = RELEASE / "tracks" / "CH_StGallen_Wil.json"
KISS = RELEASE / "trains" / "CH_Stadler_KISS_SBB.json"
YIZHUANG = RELEASE / "tracks" / "CN_Songjiazhuang_Yizhuang.json"
BEIJING = RELEASE / "trains" / "CN_Beijing_Subway.json"


def timed(journey, track=TRACK, train=KISS, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        return timed_journey_from_ttobench(journey, track, train, **kw)


def test_public_journey_reads_as_two_sections_with_their_windows():
    journey_id, track_id, points, _ = read_timing_points(JOURNEY)
    assert (journey_id, track_id, len(points)) == ("CH_StGallen_Wil_Journey_01", "CH_StGallen_Wil", 6)
    t = timed(JOURNEY)
    # the stop at 15000 m is not one of the track's stops: sections are cut at the journey's stops
    assert t.journey.stops_m == (0.0, 15000.0, 29556.1)
    assert [c.line.length_m for c in t.journey.sections] == pytest.approx([15000.0, 14556.1])
    assert t.journey.dwell_s == (120.0,)  # earliest departure 800 s - latest arrival 680 s
    assert [len(w) for w in t.windows] == [3, 3]
    assert t.windows[0][1].min_speed_kmh == 10.0 and t.windows[0][1].max_speed_kmh is None


def _limit_time_s(start_m, end_m):
    """Time at the speed limits from one position to another, straight from the track's change points."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        track = read_track(TRACK)
    points = list(track.speed_limits) + [(track.length_m, None)]
    total = 0.0
    for (a, v), (b, _) in zip(points, points[1:]):
        lo, hi = max(a, start_m), min(b, end_m)
        if hi > lo:
            total += (hi - lo) * 3.6 / v
    return total


def test_public_journey_cannot_be_met_by_any_train():
    # after 20000 m at 1200 s at the earliest, the 9556.1 m to Wil take longer at the speed limits
    # than the 250 s left before the latest arrival 1450 s: no train meets both windows
    need = _limit_time_s(20000.0, 29556.1)
    assert need > 250.0
    with pytest.raises(TimingError, match=r"9556\.1 m take at least %.1f s.*leave 250\.0 s" % need) as err:
        solve_timed_journey(timed(JOURNEY))
    assert err.value.field == "timing point at 29556.1 m"


def _journey_dict(values):
    data = json.loads(JOURNEY.read_text())
    data["timing points"]["values"] = values
    return data


@pytest.mark.parametrize("values, field, reason", [
    ([[0, 0, 0, 0, 0], [5000, 100, 90, None, None], [29556.1, 1400, 1450, 0, 0]], "timing points.values[1]",
     "lower time"),
    ([[0, 0, 0, 0, 0], [5000, None, None, 50, 40], [29556.1, 1400, 1450, 0, 0]], "timing points.values[1]",
     "lower speed"),
    ([[0, 0, 0, 0, 0], [5000, None, None, None, None], [4000, None, None, None, None], [29556.1, 1400, 1450, 0, 0]],
     "timing points.values[2]", "ordered"),
    ([[0, 0, 0, 0, 0], [5000, None, None, None, None], [5000, None, None, None, None], [29556.1, None, None, 0, 0]],
     "timing points.values[2]", "equal positions"),
    ([[0, 0, 0, 10, None], [29556.1, 1400, 1450, 0, 0]], "timing points.values[0]", "must be stops"),
    ([[0, 0, 0, 0, 0]], "timing points.values", "at least two"),
])
def test_bad_journeys_name_the_timing_point(values, field, reason):
    with pytest.raises(CaseError, match=reason) as err:
        read_timing_points(_journey_dict(values))
    assert err.value.field == field


def test_journey_of_another_track_is_refused():
    with pytest.raises(CaseError, match="another track"):
        timed(JOURNEY, track=YIZHUANG, train=BEIJING)


def _yizhuang_journey(values):
    data = _journey_dict(values)
    data["metadata"]["associated track"] = "CN_Songjiazhuang_Yizhuang"
    data["metadata"]["id"] = "CN_Songjiazhuang_Yizhuang_test"
    return data


def test_a_binding_passing_window_gets_its_own_price_and_is_met():
    # Yizhuang stops 9 -> 10 (15757 -> 18022 m) with a latest time at mid-section: the run taking the
    # whole arrival window would pass later, so the stretch before the point is priced higher
    free = timed(_yizhuang_journey([[15757, 0, 0, 0, 0], [18022, 150, 160, 0, 0]]), YIZHUANG, BEIJING)
    free_run = solve_timed_journey(free, dx_m=5.0)
    passed = float(np.interp(1100.0, free_run.trajectories[0].position_m, free_run.trajectories[0].time_s))
    latest = np.floor(passed) - 6.0
    tight = timed(_yizhuang_journey([[15757, 0, 0, 0, 0], [16857, None, latest, 20, None],
                                     [18022, 150, 160, 0, 0]]), YIZHUANG, BEIJING)
    run = solve_timed_journey(tight, dx_m=5.0)
    assert run.all_met
    checks = {c["position_m"]: c for c in run.checks}
    assert checks[16857.0]["time_s"] <= latest + 0.5 and checks[16857.0]["speed_kmh"] >= 20.0
    assert checks[18022.0]["time_s"] == pytest.approx(160.0, abs=0.5)  # still the longest running time
    assert run.energy_kwh > free_run.energy_kwh  # the window costs energy


def test_no_reading_of_the_public_journey_makes_its_last_stretch_reachable():
    # TTOBench's journey README: times are measured from the start of the journey (s, cumulative),
    # positions are track coordinates in the track's direction. Read the other way round (positions
    # from Wil), the last 9556.1 m are the first 9556.1 m of the track run backwards: still too long.
    assert _limit_time_s(20000.0, 29556.1) == pytest.approx(345.4, abs=0.1)
    assert _limit_time_s(0.0, 29556.1 - 20000.0) > 250.0
    # at the head or the tail of a train: the deficit is 95 s, about 2.8 km at 105 km/h
    assert (_limit_time_s(20000.0, 29556.1) - 250.0) * 105 / 3.6 > 2700.0


def test_the_shipped_first_published_journey_differs_only_in_its_arrival_and_is_reachable():
    # TTOBench first published the journey ending at 25000 m; its release moved the arrival to the
    # track's end (29556.1 m) and kept the window 1400-1450 s, which made the last stretch unreachable
    from pymoo_rail.journeys.timing import check_windows_reachable

    first = json.loads(FIRST_PUBLISHED.read_text())["timing points"]["values"]
    released = json.loads(JOURNEY.read_text())["timing points"]["values"]
    assert first[:-1] == released[:-1] and first[-1][1:] == released[-1][1:]
    assert (first[-1][0], released[-1][0]) == (25000, 29556.1)
    check_windows_reachable(timed(FIRST_PUBLISHED))  # no TimingError: the windows leave enough time
    with pytest.raises(TimingError, match="29556.1"):
        check_windows_reachable(timed(JOURNEY))


@pytest.mark.slow
def test_stgallen_wil_as_first_published_is_solved_within_every_window():
    # the shipped first version of the journey: every window is met (14 s CPU)
    run = solve_timed_journey(timed(FIRST_PUBLISHED))
    assert run.all_met
    assert [c["time_ok"] and c["speed_ok"] for c in run.checks] == [True] * 6
    assert run.departures_s == (0.0, 800.0)
    for traj in run.trajectories:
        assert traj.reached and traj.speed_ms[-1] == pytest.approx(0.0, abs=1e-9)


def test_metaheuristic_form_meets_the_windows_it_reports_feasible():
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.optimize import minimize

    from pymoo_rail.journeys.timed_problem import TimedSectionProblem

    t = timed(_yizhuang_journey([[15757, 0, 0, 0, 0], [16857, None, 90, 20, None], [18022, 150, 170, 0, 0]]),
              YIZHUANG, BEIJING)
    problem = TimedSectionProblem(t, 0)
    assert problem.n_ieq_constr == 2 + 4  # limits, stop; latest and min speed at 16857 m, arrival window
    res = minimize(problem, GA(pop_size=16), ("n_gen", 4), seed=2)
    assert res.X is not None
    traj = problem.trajectory(res.X)
    t_pass = float(np.interp(1100.0, traj.position_m, traj.time_s))
    assert t_pass <= 90.0 and 150.0 <= traj.running_time_s <= 170.0


def test_toml_journey_reads_like_the_ttobench_file(tmp_path):
    from pymoo_rail.journeys import timed_journey_from_toml

    rows = json.loads(JOURNEY.read_text())["timing points"]["values"]
    keys = ("position_m", "earliest_s", "latest_s", "min_speed_kmh", "max_speed_kmh")
    text = f'name = "StGallen_Wil_toml"\ntrack = "{TRACK}"\ntrain = "{KISS}"\n'
    for row in rows:
        text += "\n[[timing_points]]\n" + "".join(f"{k} = {float(v)}\n" for k, v in zip(keys, row) if v is not None)
    path = tmp_path / "j.toml"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        from_toml = timed_journey_from_toml(path)
    from_json = timed(JOURNEY)
    assert from_toml.windows == from_json.windows
    for a, b in zip(from_toml.journey.sections, from_json.journey.sections):
        assert (a.line, a.train) == (b.line, b.train)
    path.write_text(text + "\n[[timing_points]]\nposition_m = 29600.0\nwhen = 3\n")
    with pytest.raises(CaseError, match="unknown key") as err:
        timed_journey_from_toml(path)
    assert err.value.field == "timing_points[6].when"


def _min_speed_journey(min_kmh):
    # Yizhuang stops 9 -> 10; the free optimum passes 17557 m (1800 m into the section) coasting
    # at about 47 km/h, so a minimum speed of 60 km/h there binds
    return timed(_yizhuang_journey([[15757, 0, 0, 0, 0], [17557, None, None, min_kmh, None],
                                    [18022, 160, 170, 0, 0]]), YIZHUANG, BEIJING)


def test_the_exact_solve_enforces_a_binding_minimum_speed():
    free = solve_timed_journey(_min_speed_journey(None), dx_m=5.0)
    v_free = float(np.interp(1800.0, free.trajectories[0].position_m, free.trajectories[0].speed_ms)) * 3.6
    assert v_free < 55.0  # the bound below binds
    run = solve_timed_journey(_min_speed_journey(60.0), dx_m=5.0)
    traj = run.trajectories[0]
    v = float(np.interp(1800.0, traj.position_m, traj.speed_ms)) * 3.6
    assert 60.0 <= v < 62.0  # held, by at most a speed node more than asked
    assert run.all_met and traj.running_time_s == pytest.approx(170.0, abs=0.5)
    assert run.energy_kwh > free.energy_kwh  # the bound costs energy
    assert np.all(traj.speed_ms * 3.6 <= 80.0 + 1e-6) and traj.speed_ms[-1] == pytest.approx(0.0, abs=1e-9)


def test_a_minimum_speed_above_the_speed_limit_is_refused_naming_the_point():
    with pytest.raises(TimingError, match="minimum speed 85 km/h.*limit of 80 km/h") as err:
        solve_timed_journey(_min_speed_journey(85.0), dx_m=5.0)
    assert err.value.field == "timing point at 17557 m"


def test_the_problem_form_makes_a_run_below_a_minimum_speed_infeasible():
    from pymoo_rail.journeys.timed_problem import TimedSectionProblem

    problem = TimedSectionProblem(_min_speed_journey(60.0), 0)
    column = problem.n_ieq_constr - 3  # min speed, then the arrival window's latest and earliest
    slow = np.full(problem.n_var, 30.0)  # speed codes: 30 km/h all the way
    fast = problem.xu.copy()  # flat out: above 60 km/h at 1800 m
    G = problem.evaluate(np.vstack([slow, fast]), return_values_of=["G"])
    assert G[0, column] == pytest.approx(30.0, abs=0.5)  # 60 km/h asked, 30 km/h run
    assert G[1, column] < 0.0
