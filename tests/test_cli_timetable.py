"""pymoo-rail timetable: a small NSGA-II run writes the front of energy against waiting time."""

import pandas as pd

from pymoo_rail.cli import main


def test_timetable_command_writes_a_front(tmp_path, capsys):
    code = main(["timetable", "cooperative-pair", "--trains", "2", "--headway", "120", "--pop-size", "6",
                 "--n-eval", "12", "--out", str(tmp_path)])
    assert code == 0
    front = pd.read_csv(tmp_path / "front.csv")
    assert {"net_kwh", "waiting_time_s", "traction_kwh", "shared_kwh", "shift_1_s"} <= set(front.columns)
    assert (front["net_kwh"] <= front["traction_kwh"] + 1e-9).all()
    assert (front["shift_1_s"].abs() <= 30.0).all()
    assert "TimetableProblem(cooperative-pair: 2 trains" in capsys.readouterr().out


def test_timetable_command_rejects_one_train(tmp_path, capsys):
    assert main(["timetable", "cooperative-pair", "--trains", "1", "--out", str(tmp_path)]) == 2
    assert "--trains" in capsys.readouterr().err


def test_timetable_command_runs_both_directions(tmp_path, capsys):
    code = main(["timetable", "cooperative-pair", "--trains", "2", "--directions", "2", "--pop-size", "4",
                 "--n-eval", "8", "--out", str(tmp_path)])
    assert code == 0
    out = capsys.readouterr().out
    assert "2 direction(s)" in out and "regular timetable wait 120.0 s" in out
