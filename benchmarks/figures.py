"""Rebuild the report figures (PNG, not tracked in git) that can be rebuilt from what is at hand.

A report keeps its numbers in its markdown and CSV files (tracked); its figures are regenerated.
For every script below, this runs ``python benchmarks/<script>.py --report-only`` when what the
figures are drawn from is there (committed CSVs, or the study records the script stored under
``out/``), and otherwise says which command reruns the study. Nothing is recomputed here: a
script is called only in its report mode, and only when its inputs exist, so a report is never
rebuilt from nothing.

Usage::

    python benchmarks/figures.py            # rebuild what can be rebuilt, list the rest
    python benchmarks/figures.py --list     # only say which figures can be rebuilt now
"""

from __future__ import annotations

import argparse
from pathlib import Path

from pymoo_rail.experiments.report import ScriptFigures as Figures

ROOT = Path(__file__).resolve().parents[1]


SUITE_CASES = ("metro-a", "ttobench-ref", "ttobench-ref-downhill", "ttobench-ref-limit120", "ttobench-ref-uphill",
               "ttobench-songjiazhuang-xiaocun", "ttobench-wanyuan-rongjing", "ttobench-xiaohongmen-jiugong",
               "yizhuang", "yizhuang-ttobench")
PROFILES = tuple(f"yizhuang_seed000_profile_{a}_{p}.png" for a in ("abc", "moabc")
                 for p in ("equal-10", "equal-20", "non-equal"))

FIGURES = (
    Figures("moabc_zdt", ("moabc_zdt_fronts.png", "moabc_zdt_igd.png"), "out/moabc_zdt",
            from_committed=("moabc_zdt_igd.png",)),
    Figures("grnsga2_zdt", tuple(f"grnsga2_zdt{k}_fronts.png" for k in (1, 2, 3, 4)), "out/grnsga2_zdt"),
    Figures("abc_functions", tuple(f"abc_functions_d{d}-it{it}.png" for d, it in ((10, 500), (20, 1000), (30, 1000),
                                                                                 (30, 3000), (50, 5000))),
            "out/abc_functions"),
    Figures("emu_wuguang", tuple(f"emu_wuguang_{f}.png" for f in ("fronts", "fronts_overlay", "fronts_zoom",
                                                                   "box_hv", "profile")), "out/emu_wuguang"),
    Figures("yizhuang_seed000", ("yizhuang_seed000_front.png", "yizhuang_seed000_convergence.png") + PROFILES,
            "out/yizhuang_seed000"),
    Figures("metro_table3", ("metro_table3.png",), "out/metro_table3"),
    Figures("metro_controllers", ("metro_controllers_fig9.png",), "out/metro_controllers"),
    Figures("suite", tuple(f"suite_{c}-bi.png" for c in SUITE_CASES), "out/suite"),
    Figures("closed_loop_study", ("closed_loop_study.png",), "out/closed_loop_study"),
    Figures("journeys", ("journeys.png",)),
    Figures("optimal", ("optimal_front.png", "optimal_profile.png")),
    Figures("efficiency_study", ("efficiency_study.png",)),  # written where --figure says
    Figures("tracking", ("tracking_metro_a.png",), args=("metro-a",)),
    Figures("tracking", ("tracking_yizhuang_profiles.png", "tracking_yizhuang_table.png"), args=("yizhuang",)),
)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="only list what can be rebuilt and what needs a rerun")
    args = parser.parse_args(argv)
    failed = 0
    for entry in FIGURES:
        if not entry.ready(ROOT):
            print(f"{entry.script}: needs a rerun (`{entry.command}`): {', '.join(entry.figures)}")
            continue
        records = entry.has_records(ROOT)
        names = entry.figures if records else entry.from_committed
        rest = [name for name in entry.figures if name not in names]
        print(f"{entry.script}: {'would rebuild' if args.list else 'rebuilding'} {', '.join(names)}"
              + (f"; needs a rerun (`{entry.command}`): {', '.join(rest)}" if rest else ""))
        if not args.list:
            failed += entry.rebuild(ROOT) != 0
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
