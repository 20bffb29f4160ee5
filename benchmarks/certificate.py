"""The certificate's parts where the committed optimiser results came closest to the reference.

For each case and running time: the default run and its certificate (``energy_bound_kwh``) with
its parts (``OptimalSolver.last_bound_parts``: the two-grid part, the weak-duality gap of a moved
run, the cost of kept regimes, the untied run's advantage), beside runs on finer speed grids and
without the tie rule, all moved to the default run's time along the front's slope. The lower
estimate ``energy - certificate`` should lie below all of them.

Usage: ``python benchmarks/certificate.py`` (about a minute of CPU). Writes
``benchmarks/reports/certificate.md``.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.journeys import journey_from_ttobench
from pymoo_rail.experiments.report import markdown, write_report
from pymoo_rail.optimal import OptimalSolver

REPORT = Path(__file__).resolve().parent / "reports" / "certificate.md"
VARIANTS = ({"n_speeds": 100}, {"n_speeds": 400}, {"n_speeds": 800}, {"tie_j": 0.0})


def cases() -> list:
    """(label, case, running time s): wuguang-crh3 where the punctual switching-point members lay, and
    the Yizhuang line's section 1-2 where strategy-search runs lay closest below the reference."""
    section = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES).sections[1]
    return [("wuguang-crh3", load_case("wuguang-crh3"), 1050.53), ("Yizhuang section 1-2", section, 119.432943)]


def rows() -> list[dict]:
    """One row per case: the default run, its certificate and parts, and the other runs at its time."""
    out = []
    for label, case, t in cases():
        solver = OptimalSolver(case)
        tr = solver.profile(t)
        row = {"case": label, "time_s": tr.running_time_s, "energy_kwh": tr.energy.net_kwh,
               "moved": bool(tr.summary["adjusted"]), "certificate_kwh": tr.summary["energy_bound_kwh"],
               **solver.last_bound_parts}
        row["lower_estimate_kwh"] = row["energy_kwh"] - row["certificate_kwh"]
        for settings in VARIANTS:
            other = OptimalSolver(case, certify=False, **settings).profile(t)
            moved = other.summary["lambda_w"] * (other.running_time_s - tr.running_time_s) / J_PER_KWH
            name = ", ".join(f"{k}={v:g}" for k, v in settings.items())
            row[f"{name} kWh"] = other.energy.net_kwh + moved
        out.append(row)
    return out


def main() -> None:
    table = pd.DataFrame(rows()).set_index("case").T.reset_index().rename(columns={"index": "figure"})
    text = ["# The certificate's parts", "", "Written by `python benchmarks/certificate.py`: the default run (200 speed "
            "nodes, `tie_j` = 100 J) and its certificate with its parts, beside finer grids and the run without the "
            "tie rule, all moved to the default run's time along the front's slope. The certificate is the grid part "
            "plus the floor plus the largest of the other three.", "", markdown(table), ""]
    write_report(REPORT, text, newline=False)
    print("\n".join(text))


if __name__ == "__main__":
    main()
