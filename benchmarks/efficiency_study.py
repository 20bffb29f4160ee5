"""ms-eetc's efficiency study beside pymoo-rail's exact solver: perfect, static and dynamic efficiency.

Kouzoupis et al. (Transportation Research Part C 2023, fig. 5; ms-eetc's ``simulations/figure5.py``):
the VIRM6 intercity on the first 8.5 km of TTOBench track 00_var_speed_limit_100, from 1 m/s to
100 km/h, with time reserves over ms-eetc's minimum time (272.4726 s). Each solver plans the optimal
run under three efficiency models (perfect: 1 both ways; static: 73 % both ways; dynamic: ms-eetc's
losses at the operating point, motor and converter maps, 96 % gear, transformer, 27 kW auxiliaries)
and each run is costed under the dynamic model. pymoo-rail's dynamic model is a pair of efficiency
maps sampled from ms-eetc's own loss function (``pymoo_rail.model.efficiency.maps_from_losses``).

Usage: ``python benchmarks/efficiency_study.py --mseetc /tmp/mseetc [--mseetc-python PY]
[--reserves 10 20 30] [--intervals 300] [--figure /tmp/efficiency_study.png]``. Writes
``benchmarks/reports/efficiency_study.md``; the figure (optimal runs side by side) is not tracked.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.efficiency_study import findings, reserve_rows, sampled_models
from pymoo_rail.experiments.report import markdown, write_filled
from pymoo_rail.optimal import efficiency_study as es

HERE = Path(__file__).resolve().parent
REPORT = HERE / "reports" / "efficiency_study.md"
TEMPLATE = HERE / "templates" / "efficiency_study.md"
BASE_CASE = HERE / "cases" / "intercity-var-limit-100.toml"


def write_report(table: pd.DataFrame, held: int, args) -> str:
    """The report (set-up, the table, and what the differences are), written to ``args.report``."""
    return write_filled(args.report, TEMPLATE, {
        "intervals": args.intervals, "reserves": " ".join(f"{r:g}" for r in args.reserves), "held": held,
        "table": markdown(table), **findings(table)})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mseetc", type=Path, required=True, help="an ms-eetc checkout")
    parser.add_argument("--mseetc-python", default=sys.executable, help="interpreter with casadi")
    parser.add_argument("--reserves", type=float, nargs="+", default=[10.0, 20.0, 30.0], help="time reserves (%%)")
    parser.add_argument("--intervals", type=int, default=300, help="ms-eetc's N")
    parser.add_argument("--figure", type=Path, default=Path("/tmp/efficiency_study.png"), help="the runs drawn")
    parser.add_argument("--report", type=Path, default=REPORT)
    args = parser.parse_args()
    case = es.study_case(load_case(BASE_CASE))
    models, held = sampled_models(args.mseetc, args.mseetc_python, args.intervals, case)
    rows, panels = [], []
    for reserve in args.reserves:
        reserve_table, runs = reserve_rows(args.mseetc, args.mseetc_python, args.intervals, case, models, reserve)
        rows += reserve_table
        panels.append((f"time reserve {reserve:g} %", runs))
    print(write_report(pd.DataFrame(rows), held, args))
    from pymoo_rail.plotting import plot_speed_runs, save_figure

    print("figure:", save_figure(plot_speed_runs(panels), args.figure))


if __name__ == "__main__":
    main()
