"""experiments.suite_report: which seeds a report uses, and how far members go below a certified front."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.experiments import Study, algorithm, problem
from pymoo_rail.experiments.suite_report import below_extent, complete_seeds, mean_ranks, seed_ranges


class LineFront:
    """A certified front ``E*(T) = 100 - T`` on [10, 50] s with a certificate of 0.5 kWh (duck-typed)."""

    def energy_at(self, t):
        t = np.asarray(t, dtype=float)
        return 100.0 - t, np.full(t.shape, 0.5)

    def below_certificate(self, t, e):
        inside = (t >= 10.0) & (t <= 50.0)
        optimum, bound = self.energy_at(t)
        return inside, inside & (e < optimum - bound)


def test_seed_ranges_join_consecutive_seeds():
    assert seed_ranges([1, 2, 3, 7, 9, 10]) == "1-3, 7, 9-10"
    assert seed_ranges([]) == "none"


def test_complete_seeds_leave_out_partly_run_seeds_and_say_which():
    study = Study("s", problems=[problem("zdt1"), problem("zdt2")], algorithms=[algorithm("nsga2", pop_size=10)],
                  seeds=4, budget={"n_gen": 2})
    # seeds 1 and 2 complete (2 cells each), seed 3 with one run of two, seed 4 not run
    results = pd.DataFrame({"seed": [1, 1, 2, 2, 3], "run_id": ["a", "b", "c", "d", "e"]})
    seeds, sentence = complete_seeds(results, study)
    assert seeds == [1, 2]
    assert "2 complete seeds (1-2, 4 runs)" in sentence and "seed 3 with 1 of 2 runs" in sentence
    assert "seeds 4 not run (2 runs)" in sentence
    full = pd.DataFrame({"seed": [1, 1, 2, 2, 3, 3, 4, 4], "run_id": list("abcdefgh")})
    assert complete_seeds(full, study) == ([1, 2, 3, 4], "All 8 runs are stored.")


def test_below_extent_measures_the_member_below_the_certificate():
    # at T = 20 the optimum is 80 and the certificate 0.5: 79 lies 0.5 kWh beyond it, 79.8 within it
    out = below_extent(LineFront(), [20.0, 30.0, 60.0], [79.0, 69.8, 1.0])
    assert out["excess_max_kwh"] == pytest.approx(0.5)
    assert (out["worst_t_s"], out["worst_e_kwh"]) == (20.0, 79.0)
    assert out["below_t_min_s"] == out["below_t_max_s"] == 20.0
    clean = below_extent(LineFront(), [30.0], [75.0])
    assert clean["excess_max_kwh"] == pytest.approx(-5.5) and np.isnan(clean["below_t_min_s"])
    assert np.isnan(below_extent(LineFront(), [60.0], [1.0])["excess_max_kwh"])


def test_mean_ranks_rank_medians_per_problem():
    results = pd.DataFrame({"problem": ["p", "p", "q", "q"], "algorithm": ["a", "b", "a", "b"],
                            "igd": [1.0, 2.0, 4.0, 3.0]})
    ranks = mean_ranks(results, "igd", lower_better=True)
    assert ranks.to_dict() == {"a": 1.5, "b": 1.5}
    assert mean_ranks(results.assign(igd=[1.0, 2.0, 3.0, 4.0]), "igd", True).to_dict() == {"a": 1.0, "b": 2.0}
