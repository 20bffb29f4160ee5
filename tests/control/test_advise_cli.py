"""``pymoo-rail advise``: one disturbed run with the advice printed, written and drawn; bad values named."""

import json

import pandas as pd

from pymoo_rail.cli import main


def test_advise_writes_the_advice_and_the_figure(tmp_path, capsys):
    code = main(["advise", "metro-a", "--planned", "80", "--delay", "3", "--restriction", "550:650:60",
                 "--announce", "300", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0
    assert "power to" in out and "brake for the stop" in out and "lateness" in out
    table = pd.read_csv(tmp_path / "advice.csv")
    assert table["text"].iloc[0].startswith("power to")
    assert json.loads((tmp_path / "advice.json").read_text())[0]["action"] == "power"
    assert (tmp_path / "advice.png").stat().st_size > 10_000


def test_advise_names_a_bad_restriction(tmp_path, capsys):
    code = main(["advise", "metro-a", "--restriction", "3000:3600:40", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "--restriction" in err and "3600" in err
    code = main(["advise", "metro-a", "--restriction", "600:40", "--out", str(tmp_path)])
    assert code == 2 and "START_M:END_M:LIMIT_KMH" in capsys.readouterr().err
