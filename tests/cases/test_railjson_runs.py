"""OSRD's realistic rolling stocks driven flat-out and optimally, on an OSRD line and on a generated
line, every run checked: limits held over the train length, no traction in neutral sections or
electrification gaps, stopped at the platform, work balance closed."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from pymoo_rail.cases import generate_case, load_train, railjson_case
from pymoo_rail.experiments.osrd_fleet import KINDS, MODES
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.checks import check_run

DATA = Path(__file__).resolve().parents[1] / "data" / "osrd"
STOCKS = sorted((DATA / "rolling_stocks").glob("*.json"))
# North_East -> West on small_infra (45.8 km): 300 km/h but 142 km/h over [4500, 5000] m, where a
# train faster than 142 km/h must hold it until its tail has left the restriction
RESTRICTION_M = (4500.0, 5000.0, 142.0)
# the trains fast enough to reach it flat out (the others top out below it or are still accelerating)
HELD_BY_THE_TAIL = {"emu-regional-train", "high-speed-train", "intercity-train", "night-train"}


def _check_physics(case, trajectory) -> None:
    check = check_run(trajectory, case)
    assert trajectory.reached and trajectory.speed_ms[-1] == 0.0
    assert check.passes(), check
    s = trajectory.summary
    # work balance: traction - braking = kinetic + resistance + potential (ends at rest)
    kinetic = 0.5 * case.train.effective_mass_kg * trajectory.speed_ms[-1] ** 2
    balance = s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] - kinetic
    assert abs(balance) <= 1e-6 * s["traction_work_j"]


def _drive(case) -> tuple[float, float]:
    """Flat-out and optimal (15 % slack) runs, both checked; (minimum time s, optimal energy kWh)."""
    fastest = Simulator(case).flat_out()
    _check_physics(case, fastest)
    optimal = optimal_profile(case, 1.15 * fastest.running_time_s)
    _check_physics(case, optimal)
    assert abs(optimal.running_time_s - 1.15 * fastest.running_time_s) <= 0.5
    # slack buys energy: the optimal run needs less than the fastest
    assert optimal.energy.net_kwh < fastest.energy.net_kwh
    return fastest.running_time_s, optimal.energy.net_kwh


def _drive_restricted(stock: Path) -> None:
    """Flat-out and optimal on North_East -> West; a train faster than the restriction holds it
    over its whole length: <= 142 km/h until the tail leaves 5000 m, faster after."""
    case = _osrd_case(stock, "North_East_station", "West_station")
    assert RESTRICTION_M in case.line.speed_limits
    _drive(case)
    fastest = Simulator(case).flat_out()
    start, end, limit_kmh = RESTRICTION_M
    behind = (fastest.position_m >= start) & (fastest.position_m < end + case.train.length_m)
    assert fastest.speed_ms[behind].max() * 3.6 <= limit_kmh + 1e-6
    if stock.stem in HELD_BY_THE_TAIL:  # the restriction binds: at 142 km/h until the tail clears, faster after
        assert fastest.speed_ms[behind].max() * 3.6 == pytest.approx(limit_kmh, abs=1e-6)
        assert fastest.speed_ms[fastest.position_m > end + case.train.length_m].max() * 3.6 > limit_kmh + 5.0


def test_an_intercity_train_holds_a_restriction_until_its_tail_clears_it():
    case = _osrd_case(DATA / "rolling_stocks" / "intercity-train.json", "North_East_station", "West_station")
    fastest = Simulator(case).flat_out()
    _check_physics(case, fastest)
    start, end, limit_kmh = RESTRICTION_M
    tail_inside = (fastest.position_m >= end) & (fastest.position_m < end + case.train.length_m)
    # the head has left the restriction, the tail has not: the run stays at 142 km/h for those 200 m
    assert fastest.speed_ms[tail_inside] * 3.6 == pytest.approx(limit_kmh, abs=1e-6)
    assert fastest.speed_ms[fastest.position_m > end + case.train.length_m + 200.0].max() * 3.6 > limit_kmh


def _osrd_case(stock: Path, start: str, end: str):
    return railjson_case(DATA / "infras" / "small_infra.json", stock, from_point=start, to_point=end,
                         planned_time_s=3600.0, mode=MODES.get(stock.stem))


def _generated_case(stock: Path, seed: int):
    # from rest to a stop at the platform (generated lines may start and end moving)
    return replace(generate_case(seed, KINDS[stock.stem]), train=load_train(stock, mode=MODES.get(stock.stem)),
                   initial_speed_ms=0.0, final_speed_ms=0.0)


def test_an_emu_on_an_osrd_line_and_the_touristic_train_on_a_generated_line():
    # a curved 6.8 km OSRD path, and a generated 1.9 km metro line
    emu = _osrd_case(DATA / "rolling_stocks" / "emu-regional-train.json", "North_station", "South_station")
    assert emu.line.curves and emu.line.curve_model == "osrd"
    _drive(emu)
    _drive(_generated_case(DATA / "rolling_stocks" / "touristic-train.json", 1))


def test_the_neutral_section_is_crossed_without_traction():
    # Mid_East -> West ends on TA0 (1500 V only): the 25 kV high-speed train coasts its last 1300 m
    case = _osrd_case(DATA / "rolling_stocks" / "high-speed-train.json", "Mid_East_station", "West_station")
    assert case.line.neutral_sections == ((25000.0, 26300.0),)
    fastest = Simulator(case).flat_out()
    _check_physics(case, fastest)
    inside = (fastest.position_m[:-1] >= 25000.0)
    assert inside.any() and fastest.force_n[:-1][inside].max() <= 0.0


@pytest.mark.slow
@pytest.mark.parametrize("stock", STOCKS, ids=[p.stem for p in STOCKS])
def test_every_realistic_train_drives_an_osrd_line_and_a_generated_line(stock):
    # 26.3 km of small_infra with +-6 permille and a neutral section; a generated line of the
    # train's kind (seed 0: 1.9 to 37 km, climbs and descents, curves, neutral sections)
    _drive(_osrd_case(stock, "Mid_East_station", "West_station"))
    _drive(_generated_case(stock, 0))


@pytest.mark.slow
@pytest.mark.parametrize("stock", STOCKS, ids=[p.stem for p in STOCKS])
def test_every_realistic_train_drives_an_osrd_line_with_a_restriction(stock):
    # the 26.3 km path above has one limit (300 km/h): this 45.8 km one has a 142 km/h restriction
    # that the faster trains (EMU, intercity, night, high-speed) must hold over their whole length
    _drive_restricted(stock)


def test_the_fleet_is_the_eleven_osrd_stocks():
    # the slow tests above are parametrised over STOCKS: all eleven, each with a kind of generated line
    assert len(STOCKS) == 11 and set(KINDS) == {p.stem for p in STOCKS}
