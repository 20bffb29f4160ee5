"""The closed-loop study's worlds that cannot be on time: how the policy's arrival compares with a race from the start.

A world "cannot be on time" when even the real train flat out from its late departure, the
restriction known from the start, misses the plan (``can_be_on_time`` false in the study's rows).
The time-optimal recovery races from the departure whatever happens; the policy drives the run
0.25 s behind the fastest only from a decision where it knows the train is late. This module
compares the two in those worlds (kept apart from :mod:`pymoo_rail.experiments.loop_study`, whose
source is part of every stored world's fingerprint).
"""

from __future__ import annotations

import pandas as pd

from pymoo_rail.experiments.report import markdown_rows

# an arrival this much after the recovery's counts as later than the race from the start
LATER_THAN_RACE_S = 2.0


def late_world_arrivals(runs: pd.DataFrame, controller: str = "optimal_controls",
                        race: str = "recovery") -> pd.DataFrame:
    """Per case, over the worlds that cannot be on time: ``controller``'s running time minus ``race``'s.

    Columns: ``case``, ``worlds``, ``median_s``, ``max_s`` (the difference, s; negative: earlier
    than the race), ``later_than_race`` (worlds over :data:`LATER_THAN_RACE_S`), ``restricted_among_later``
    and ``energy_saved_pct`` (median of ``1 - energy / race's energy``, %).
    """
    rows = []
    for case, g in runs[~runs["can_be_on_time"].astype(bool)].groupby("case", sort=False):
        mine = g[g["controller"] == controller].set_index("run")
        other = g[g["controller"] == race].set_index("run").reindex(mine.index)
        later = mine["running_time_s"] - other["running_time_s"]
        over = later > LATER_THAN_RACE_S
        rows.append({"case": case, "worlds": len(later), "median_s": float(later.median()),
                     "max_s": float(later.max()), "later_than_race": int(over.sum()),
                     "restricted_among_later": int(mine["restricted"][over].astype(bool).sum()),
                     "energy_saved_pct": float((100.0 * (1.0 - mine["net_kwh"] / other["net_kwh"])).median())})
    return pd.DataFrame(rows)


def late_worlds_markdown(runs: pd.DataFrame) -> str:
    """:func:`late_world_arrivals` of the policy's own controls against the recovery, as markdown."""
    table = late_world_arrivals(runs)
    rows = [[r["case"], r["worlds"], f"{r['median_s']:+.2f}", f"{r['max_s']:+.2f}",
             f"{r['later_than_race']} ({r['restricted_among_later']} restricted)", f"{r['energy_saved_pct']:.1f} %"]
            for _, r in table.iterrows()]
    return markdown_rows(["case", "worlds too late", "median arrival after the recovery s", "largest s",
                          f"over {LATER_THAN_RACE_S:g} s later", "median energy saved"], rows)


__all__ = ["LATER_THAN_RACE_S", "late_world_arrivals", "late_worlds_markdown"]
