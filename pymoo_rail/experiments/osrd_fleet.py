"""OSRD's realistic fleet: each rolling stock's fastest run against its energy-optimal one.

OSRD (railjson) ships realistic rolling stocks in its test data and computes the mechanical energy
of a run, but does no optimisation. :func:`fleet_rows` loads each (``pymoo_rail.cases.load_train``),
runs it on an OSRD line and on a generated line of its kind (``generate_case(0, kind)``, from rest to
rest) flat out and at the minimum energy for ``SLACK`` x that running time, every run checked
(``check_run``). ``benchmarks/osrd_fleet.py`` prints the table.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from pymoo_rail.cases import generate_case, load_train, railjson_case
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.checks import check_run

MODES = {"high-speed-train": "25000V"}  # its default 1500 V mode has no traction on small_infra's 25 kV
KINDS = {"commuter-train": "suburban", "d-tram-train": "metro", "dmu-regional-train": "suburban",
         "e-tram-train": "metro", "emu-regional-train": "suburban", "freight-train": "intercity",
         "high-speed-train": "high-speed", "intercity-train": "intercity", "light-freight-train": "intercity",
         "night-train": "intercity", "touristic-train": "metro"}
SLACK = 1.15


def runs(case) -> tuple[float, float, float]:
    """(minimum running time s, its energy kWh, optimal energy kWh at SLACK x the minimum)."""
    fastest = Simulator(case).flat_out()
    optimal = optimal_profile(case, SLACK * fastest.running_time_s)
    for trajectory in (fastest, optimal):
        if not check_run(trajectory, case).passes():
            raise RuntimeError(f"{case.name}: a run fails its checks")
    return fastest.running_time_s, fastest.energy.net_kwh, optimal.energy.net_kwh


def fleet_lines(data: str | Path, from_point: str = "Mid_East_station", to_point: str = "West_station"):
    """One markdown row per rolling stock of ``data``/rolling_stocks (OSRD's test data layout), on
    ``data``/infras/small_infra.json from ``from_point`` to ``to_point`` and on a generated line of its kind."""
    data = Path(data)
    for path in sorted((data / "rolling_stocks").glob("*.json")):
        mode = MODES.get(path.stem)
        osrd = railjson_case(data / "infras" / "small_infra.json", path, from_point=from_point,
                             to_point=to_point, planned_time_s=3600.0, mode=mode)
        generated = replace(generate_case(0, KINDS[path.stem]), train=load_train(path, mode=mode),
                            initial_speed_ms=0.0, final_speed_ms=0.0)
        t1, e1, o1 = runs(osrd)
        t2, e2, o2 = runs(generated)
        yield (f"| {osrd.train.name} | {osrd.train.mass_t:g} | {t1:.0f} | {e1:.1f} | {o1:.1f} | {1 - o1 / e1:.0%} "
               f"| {KINDS[path.stem]}, {generated.line.length_m / 1000:.1f} | {t2:.0f} | {e2:.1f} | {o2:.1f} "
               f"| {1 - o2 / e2:.0%} |")
