"""Trains sharing braking energy in one supply section: 2, 4 and 8 trains (``examples/timetable.toml``).

Runs the study file through ``pymoo_rail.experiments.run_study`` (records in
``out/timetable_study/``, not tracked; finished runs are skipped when run again) and writes
``reports/timetable.md``: per number of trains, the least net substation energy found, its saving
against the reference (every train exactly optimal alone, nothing shared: ``n_trains`` times the
exact baseline of the line, ``exact_baseline``), what was shared, and the waiting time it costs
against the regular timetable.

Usage: ``python benchmarks/timetable.py [--workers 2] [--work DIR] [--out DIR] [--report-only]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.report import add_study_options, lower_priority, write_filled
from pymoo_rail.experiments.script import study_results
from pymoo_rail.experiments.study_file import read_study
from pymoo_rail.problems import TimetableProblem

ROOT = Path(__file__).parent
REPORTS = ROOT / "reports"


def report_rows(results, per_train) -> list[str]:
    """One row per run: least energy against the reference, and the waits at both ends of the front."""
    rows = []
    results["directions"] = [int(spec.get("directions", 1)) for spec in results["problem_spec"]]
    for _, r in results.sort_values(["directions", "n_var", "seed"]).iterrows():
        F = r["F"]
        n_trains = int(r["problem_spec"]["n_trains"])
        ref = float(sum(per_train[k % r["directions"]] for k in range(n_trains)))
        i, j = int(np.argmin(F[:, 0])), int(np.argmin(F[:, 1]))
        rows.append(f"| {n_trains} | {r['directions']} | {r['seed']} | {len(F)} | {F[i, 0]:.3f} | {ref:.3f} | "
                    f"{100 * (1 - F[i, 0] / ref):.2f} % | {ref - F[i, 0]:.3f} | {F[i, 1]:.1f} | "
                    f"{F[j, 1]:.1f} | {F[j, 0]:.3f} |")
    return rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_study_options(parser, ROOT.parent / "out" / "timetable_study", REPORTS, workers=True)
    args = parser.parse_args(argv)
    lower_priority()
    study = read_study(ROOT.parent / "examples" / "timetable.toml")
    results = study_results(study, args, seed_major=True)
    # each train exactly optimal alone on the study's grid, in its own direction (the other way climbs
    # where this one descends)
    dx_m = float(results["problem_spec"].iloc[0].get("dx_m", 1.0))
    per_train = TimetableProblem(load_case("cooperative-pair"), 2, 120.0, dx_m=dx_m,
                                 directions=2).references_per_train_kwh()
    print(write_filled(args.out / "timetable.md", ROOT / "templates" / "timetable.md", {
        "reference_kwh": f"{per_train[0]:.3f}", "reference_back_kwh": f"{per_train[1]:.3f}",
        "rows": "\n".join(report_rows(results, per_train)), "cpu_s": f"{results['cpu_time_s'].sum():.0f}"}))


if __name__ == "__main__":
    main()
