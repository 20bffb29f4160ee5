"""The shifted sample of ``benchmarks/certificate_shifted.py``: its times and its verdicts."""

import pandas as pd
import pytest

from pymoo_rail.experiments.certificate_check import EXTRA, SHIFTS, shifted_sample, shifted_time_s, summary
from pymoo_rail.experiments.peers import comparable_case
from pymoo_rail.optimal import min_running_time


def test_one_shift_per_line_in_turn_and_the_counterexample():
    sample = shifted_sample(24)
    assert len(sample) == 24 + len(EXTRA)
    assert [seed for seed, _ in sample[:24]] == list(range(24))
    assert {shift for _, shift in sample[:24]} == set(SHIFTS)
    assert (5, (1.5, 0.2, 0.0)) in sample


def test_the_shifted_time_is_factor_times_the_minimum_plus_seconds_then_share():
    case = comparable_case(3)
    t_min = min_running_time(case)
    assert shifted_time_s(case, (1.5, 0.2, 0.0)) == pytest.approx(1.5 * t_min + 0.2, abs=1e-9)
    assert shifted_time_s(case, (1.05, 0.0, 0.01)) == pytest.approx(1.05 * t_min * 1.01, abs=1e-9)


def test_the_summary_names_every_answer_below_the_truth_beyond_its_certificate():
    table = pd.DataFrame({"seed": [5, 1], "time_s": [1954.945, 888.073], "bound_kwh": [0.062, 0.2],
                          "margin_kwh": [-0.072, 0.1], "cpu_s": [0.5, 0.3]})
    text = summary(table)
    assert "1 violations (seed 5 at 1954.945 s)" in text and "smallest margin -0.0720" in text
