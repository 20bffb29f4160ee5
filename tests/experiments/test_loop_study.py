"""The closed-loop study at full size: one checked record per world, resumable (``pymoo_rail.experiments.loop_study``)."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.control.study import loop_runs
from pymoo_rail.model.errors import FieldError


@pytest.fixture(scope="module")
def metro():
    return load_case("metro-a")


def test_the_study_is_stored_world_by_world_and_resumes(metro, tmp_path):
    from pymoo_rail.control import PID
    from pymoo_rail.experiments.loop_study import LoopStudyCase, load_loop_rows, run_loop_study

    item = LoopStudyCase(metro, 80.0, 2, tuned={"pid": PID(kp=0.3, ki=0.02, kd=0.0)})
    names = ("tracking_pid", "tracking_tuned_pid", "optimal_controls")
    said = []
    rows = run_loop_study([item], 5, tmp_path, chunk=1, controllers=names, say=said.append)
    assert said[0] == "0 worlds stored, 2 to compute in 2 chunks"
    assert sorted(set(rows["run"])) == [0, 1] and len(rows) == 6
    tuned = rows[rows["controller"] == "tracking_tuned_pid"]
    assert (tuned["net_kwh"].to_numpy() != rows[rows["controller"] == "tracking_pid"]["net_kwh"].to_numpy()).all()
    # the same worlds as the study's own runs, so a resumed study matches one run in one go
    direct = loop_runs(metro, 2, seed=5, controllers=names, planned_time_s=80.0, tuned=item.tuned)
    np.testing.assert_allclose(rows["net_kwh"].to_numpy(), direct["net_kwh"].to_numpy())
    again = run_loop_study([item], 5, tmp_path, chunk=1, controllers=names, say=said.append)
    assert said[-1] == "2 worlds stored, 0 to compute in 0 chunks"
    assert again.equals(rows)
    record = tmp_path / "runs" / "metro-a-seed5-world0000.json"
    record.write_text(record.read_text().replace('"run": 0', '"run": 7'))
    with pytest.raises(FieldError, match="'record' = .*altered or damaged"):
        load_loop_rows(tmp_path)


def test_loop_tests_pair_the_worlds():
    import pandas as pd

    from pymoo_rail.experiments.loop_study import loop_tests

    rng = np.random.default_rng(0)
    base = rng.uniform(1.0, 20.0, 12)  # worlds differ far more than the controllers do
    rows = []
    for name, shift in (("tracking_a", 0.0), ("tracking_b", 0.5), ("better", -0.1), ("worse", 0.1)):
        for run, b in enumerate(base):
            rows.append({"case": "c", "run": run, "controller": name, "gap_pct": b + shift, "cost_kwh": b + shift,
                         "lateness_s": 0.0})
    tests = loop_tests(pd.DataFrame(rows), ("tracking_a", "tracking_b"))
    gap = tests[tests["measure"] == "gap_pct"].set_index("controller")
    assert set(gap["against"]) == {"tracking_a"}
    # unpaired, +-0.1 would be lost in the spread of the worlds; paired, it is significant
    assert gap.loc["better", "verdict"] == "+" and gap.loc["worse", "verdict"] == "-"
    assert gap.loc["tracking_b", "verdict"] == "-"
    assert (tests[tests["measure"] == "lateness_abs_s"]["verdict"] == "=").all()


def test_the_advice_table_pairs_the_advised_run_with_the_policys_in_the_same_world():
    import matplotlib

    matplotlib.use("Agg")
    import pandas as pd

    from pymoo_rail.experiments.loop_study import advice_markdown
    from pymoo_rail.plotting import plot_gap_lateness

    runs = pd.DataFrame([{"case": "a", "controller": c, "run": r, "cost_kwh": cost, "lateness_s": 1.0, "gap_pct": 2.0}
                         for r, (adv, opt) in enumerate([(100.5, 100.0), (103.0, 100.0), (99.0, 100.0)])
                         for c, cost in (("advice", adv), ("optimal_controls", opt))])
    rows = advice_markdown(runs.iloc[::-1]).splitlines()  # paired by world, not by order
    assert rows[0] == "| case | worlds | median extra cost | 90th percentile | worlds over 1 % |"
    assert rows[2] == "| a | 3 | +0.50 % | +2.50 % | 1 |"  # extra costs -1, +0.5, +3 %
    fig = plot_gap_lateness(runs, ("advice", "optimal_controls"))
    assert len(fig.axes) == 1 and len(fig.axes[0].collections) == 4  # each controller: its runs and its median


def test_the_latency_and_disturbance_tables_say_what_the_rows_hold():
    import pandas as pd

    from pymoo_rail.experiments.loop_study import disturbance_markdown, latency_markdown

    row = {"case": "a", "length_km": 2.34, "replans": 16, "fastest": 1, "build_s": 0.5, "loop_median_ms": 4.0,
           "loop_p90_ms": 200.0, "warm_median_ms": 4.0, "warm_p90_ms": 100.0, "first_half_ms": 20.0,
           "on_time_plans_ms": 3.0, "fresh_s": 0.4}
    assert latency_markdown([row]).splitlines()[2] == (
        "| a | 2.3 | 16 (1) | 0.50 | 4.0 / 200.0 | 4.0 / 100.0 | 20.0 | 3.0 | 0.40 | 100x | 20x |")
    runs = pd.DataFrame([{"case": "a", "world": "none", "controller": c, "gap_pct": g, "lateness_s": late}
                         for c, g, late in (("pid", 1.234, -0.5), ("policy", 0.1, 1.0))])
    assert disturbance_markdown(runs, ("policy", "pid")).splitlines() == [
        "| case | disturbance | policy | pid |", "|---|---|---|---|", "| a | none | 0.10 % (+1.00 s) | 1.23 % (-0.50 s) |"]


def test_worlds_of_other_code_are_set_aside_and_computed_again(metro, tmp_path):
    import json

    from pymoo_rail.experiments.loop_study import LoopStudyCase, load_loop_rows, loop_code, run_loop_study
    from pymoo_rail.experiments.store import record_checksum

    item = LoopStudyCase(metro, 80.0, 1)
    names = ("optimal_controls",)
    rows = run_loop_study([item], 5, tmp_path, controllers=names, say=lambda _: None)
    path = tmp_path / "runs" / "metro-a-seed5-world0000.json"
    record = json.loads(path.read_text())
    assert record["code"] == loop_code()
    # the same world, as stored by other code (its checksum right): not served
    record.pop("checksum")
    record["code"] = dict(record["code"], **{"pymoo-rail code": "sha256:other"})
    record["rows"][0]["net_kwh"] = -1.0
    record["checksum"] = record_checksum(record)
    path.write_text(json.dumps(record))
    assert load_loop_rows(tmp_path).empty
    said = []
    again = run_loop_study([item], 5, tmp_path, controllers=names, say=said.append)
    assert said[0].startswith("1 worlds computed by other code set aside in")
    assert len(list((tmp_path / "stale").glob("metro-a-seed5-world0000.json.*"))) == 1
    cols = ["run", "controller", "net_kwh", "lateness_s", "gap_pct"]  # all but the CPU times
    assert again[cols].equals(rows[cols]) and again["net_kwh"].iloc[0] > 0.0


def test_the_code_fingerprint_covers_the_loop_and_not_the_rest_of_the_package():
    from pymoo_rail.experiments.inputs import package_digest
    from pymoo_rail.experiments.loop_study import LOOP_CODE_PARTS, loop_code

    assert loop_code()["pymoo-rail code"] == package_digest(LOOP_CODE_PARTS)
    assert package_digest(LOOP_CODE_PARTS) != package_digest()  # the whole package is more
    assert package_digest(("control",)) != package_digest(("control", "sim"))
