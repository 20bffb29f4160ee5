"""experiments.cooperative: the offsets study as a Study and the sharing potential of traced runs."""

import numpy as np
import pytest

from pymoo_rail.experiments.cooperative import offsets_study, problem_label, sharing_potential
from pymoo_rail.sim.cooperation import ClockedRun

J_PER_KWH = 3.6e6


def _run(times_s, traction_j, regen_j, departure_s):
    t = np.asarray(times_s, dtype=float)
    return ClockedRun(time_s=t, position_m=10.0 * t, speed_ms=np.full(t.shape, 10.0),
                      traction_j=np.asarray(traction_j, dtype=float), regen_j=np.asarray(regen_j, dtype=float),
                      departure_s=departure_s, start_m=0.0)


def test_sharing_potential_of_a_stop_over_a_departure():
    # A draws 20 kJ over [0, 10) s and regenerates 10 kJ over [10, 20) s; B leaves at 15 s and draws
    # 30 kJ over [15, 25) s: A's regeneration over [15, 20) s (5 kJ) meets B on the move and drawing
    a = _run([0.0, 10.0, 20.0], [20e3, 0.0], [0.0, 10e3], 0.0)
    b = _run([0.0, 10.0, 25.0], [30e3, 0.0], [0.0, 0.0], 15.0)
    pot = sharing_potential([a, b])
    assert pot.loc[0, "regen_kwh"] == pytest.approx(10e3 / J_PER_KWH)
    assert pot.loc[0, "while_others_move_kwh"] == pytest.approx(5e3 / J_PER_KWH)
    assert pot.loc[0, "others_draw_kwh"] == pytest.approx(5e3 / J_PER_KWH)
    assert pot.loc[0, "braking_from_s"] == pytest.approx(10.05) and pot.loc[0, "braking_to_s"] == pytest.approx(19.95)
    assert pot.loc[1, "regen_kwh"] == 0.0 and np.isnan(pot.loc[1, "braking_from_s"])


def test_offsets_study_names_every_offset_and_gradient_factor():
    study = offsets_study("s", [1.0, 0.4], 3)
    labels = [p.label for p in study.problems]
    assert labels[:2] == [problem_label(1.0, -45.0), problem_label(1.0, 0.0)] and len(labels) == 10
    assert labels[5] == "phi=0.4 x=-45"
    assert (study.budget.kind, study.budget.value) == ("n_eval", 6000) and study.seeds == (1, 2, 3)


def test_paper_encoding_study_uses_the_seed_problem():
    from pymoo_rail.experiments.registry import PROBLEMS

    study = offsets_study("p", [1.0], 2, paper_encoding=True)
    assert {p.name for p in study.problems} == {"cooperative_seed"} and "cooperative_seed" in PROBLEMS
    with pytest.raises(ValueError, match=r"phi = 0.4"):
        offsets_study("p", [0.4], 2, paper_encoding=True)


def test_best_clocked_runs_resimulates_the_least_energy_member_of_the_offset():
    import pandas as pd

    from pymoo_rail.experiments.cooperative import best_clocked_runs

    simulated = []

    class Problem:
        def __init__(self, offset_s):
            self.offset_s = offset_s

        def simulate(self, X):
            simulated.append((self.offset_s, X.tolist()))
            return {"clocked": [("runs of", X[0, 0])]}

    results = pd.DataFrame({"problem": [problem_label(1.0, 45.0), problem_label(1.0, 45.0), problem_label(1.0, 0.0)],
                            "F": [np.array([[5.0], [4.0]]), np.array([[3.0], [6.0]]), np.array([[1.0]])],
                            "X": [np.array([[10.0], [11.0]]), np.array([[12.0], [13.0]]), np.array([[14.0]])]})
    assert best_clocked_runs(results, 45.0, Problem) == ("runs of", 12.0)  # run 2, its first member
    assert simulated == [(45.0, [[12.0]])]
    assert best_clocked_runs(results, 90.0, Problem) is None and best_clocked_runs(None, 45.0, Problem) is None


def test_without_stored_studies_only_the_exact_runs_show_what_there_is_to_share():
    from pymoo_rail.cases import load_case
    from pymoo_rail.experiments.cooperative import sharing_rows
    from pymoo_rail.problems.cooperative import SEED_001_OFFSETS_S
    from pymoo_rail.problems.cooperative_baseline import exact_baseline

    case = load_case("cooperative-pair")
    rows = sharing_rows(case, None, None, exact_baseline(case))
    assert [(x, label) for x, label, _ in rows] == [(x, "exact, alone") for x in SEED_001_OFFSETS_S]
    for _, _, potential in rows:
        assert len(potential) == 2 and (potential["regen_kwh"] >= potential["while_others_move_kwh"] - 1e-12).all()
