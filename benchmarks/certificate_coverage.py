"""Does the default solver's certificate cover what another node placement or a finer grid finds?

At every running time of the optimiser members ``benchmarks/reference_check.py`` reads (984 in
range), the default solver's optimum at that time (``ReferenceAtTime``: the run moved to the time
along the front's slope) and its certificate ``energy_bound_kwh`` are compared with what a run of
another solve reaches at that time (its supporting line plus ``move_remainder_kwh``, the chord
between its solves on either side), the other solve being

- ``uniform``: the speed nodes uniform in ``v^2`` (``top_bias = 0``), finer at low speed;
- ``fine``: twice the speed nodes (``n_speeds = 400``).

A difference ``default - other`` larger than the default's certificate is a miss: the certificate
did not see an error the other solve exposes. The script prints, per case and over all, how often
the other solve was lower, by how much at most, and the misses (exit status 1 if there is one).

Usage::

    nice -n 10 python benchmarks/certificate_coverage.py            # about 4 CPU minutes
    python benchmarks/certificate_coverage.py --limit 5              # the first 5 times per case

Writes ``benchmarks/reports/certificate_coverage.md``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.experiments.report import committed_members, lower_priority, markdown, member_cases, write_report

REPORTS = Path(__file__).resolve().parent / "reports"
OTHERS = {"uniform": {"top_bias": 0.0}, "fine": {"n_speeds": 400}}


def compare(table: pd.DataFrame) -> pd.DataFrame:
    """One row per case and distinct running time: the default optimum, its certificate, the others'."""
    from tqdm import tqdm

    from pymoo_rail.optimal import ReferenceAtTime

    cases = member_cases()
    rows = []
    for name, group in tqdm(list(table.groupby("case", sort=False)), desc="cases", unit="case"):
        times = np.sort(group["running_time_s"].round(3).unique())
        refs = {"default": ReferenceAtTime(cases[name])}
        refs.update({k: ReferenceAtTime(cases[name], certify=False, **s) for k, s in OTHERS.items()})
        cpu = {}
        answers = {}
        for label, ref in refs.items():
            t0 = time.process_time()
            answers[label] = [ref.at(float(t)) for t in times]  # increasing: each warm-starts the next
            cpu[label] = time.process_time() - t0
        for k, t in enumerate(times):
            d = answers["default"][k]
            row = {"case": name, "running_time_s": t, "default_kwh": d["optimal_kwh"],
                   "certificate_kwh": d["energy_bound_kwh"]}
            # the other solve's optimum lies between its supporting line and the chord above it: the
            # chord is the value a run of that solve reaches at this time
            row.update({f"{label}_kwh": answers[label][k]["optimal_kwh"] + answers[label][k]["move_remainder_kwh"]
                        for label in OTHERS})
            rows.append(row)
        print(f"{name}: {len(times)} times, CPU s " + ", ".join(f"{k} {v:.1f}" for k, v in cpu.items()), flush=True)
    return pd.DataFrame(rows)


def summary(table: pd.DataFrame) -> tuple[pd.DataFrame, list[str]]:
    """Per case and other solve: times lower, largest difference, misses; and the worst cases as text."""
    t = table[np.isfinite(table["default_kwh"])]
    parts, lines = [], []
    for label in OTHERS:
        diff = t["default_kwh"] - t[f"{label}_kwh"]  # > 0: the other solve is lower
        miss = diff - t["certificate_kwh"]  # > 0: the certificate did not cover it
        g = t.assign(diff=diff, rel=diff / t["default_kwh"], miss=miss).groupby("case", sort=False)
        parts.append(pd.DataFrame({
            "other": label, "times": g.size(), "other lower": g["diff"].apply(lambda s: int((s > 1e-9).sum())),
            "largest lower kWh": g["diff"].max(), "largest lower %": 100 * g["rel"].max(),
            "largest certificate kWh": g["certificate_kwh"].max(),
            "misses": g["miss"].apply(lambda s: int((s > 1e-9).sum())), "worst margin kWh": -g["miss"].max(),
        }).reset_index())
        worst, worst_miss = diff.idxmax(), miss.idxmax()
        lines.append(f"- `{label}` ({', '.join(f'{k}={v:g}' for k, v in OTHERS[label].items())}): lower than the "
                     f"default at {int((diff > 1e-9).sum())} of {len(t)} times, by up to {diff[worst]:.4f} kWh "
                     f"({t.at[worst, 'case']} at {t.at[worst, 'running_time_s']:.3f} s, "
                     f"certificate {t.at[worst, 'certificate_kwh']:.4f} kWh); not covered by the certificate: "
                     f"**{int((miss > 1e-9).sum())}** (closest: margin {-miss[worst_miss]:.4f} kWh, "
                     f"{t.at[worst_miss, 'case']} at {t.at[worst_miss, 'running_time_s']:.3f} s).")
    return pd.concat(parts, ignore_index=True), lines


def main(argv=None) -> int:
    """Compare at every member time (or the first ``--limit`` per case); exit status 1 on a miss."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPORTS, help="report folder")
    parser.add_argument("--limit", type=int, default=None, help="only the first N member times of each case")
    args = parser.parse_args(argv)
    lower_priority()
    table = committed_members(REPORTS)
    if args.limit is not None:
        table = table.groupby("case", sort=False).head(args.limit)
    cpu0 = time.process_time()
    result = compare(table)
    cpu = time.process_time() - cpu0
    s, lines = summary(result)
    misses = int(s["misses"].sum())
    text = ["# The default solver's certificate against other node placements and a finer grid", "",
            "Written by `python benchmarks/certificate_coverage.py`: at every distinct running time of the optimiser "
            "members `benchmarks/reference_check.py` reads, the default solver's optimum (`ReferenceAtTime`, the run "
            "moved to the time along the front's slope) and its certificate against the same optimum solved with "
            "the speed nodes uniform in v^2 and with twice the speed nodes (each at the chord between its solves on either side of the time, the energy its runs reach there). A *miss* is another solve lower than "
            "the default by more than the default's certificate; *worst margin* = certificate - difference.", "",
            f"Times compared: {int(np.isfinite(result['default_kwh']).sum())}; misses: **{misses}**; "
            f"CPU {cpu:.0f} s.", "", *lines, "", markdown(s), ""]
    write_report(args.out / "certificate_coverage.md", text, newline=False)
    print("\n".join(text))
    return 1 if misses else 0


if __name__ == "__main__":
    raise SystemExit(main())
