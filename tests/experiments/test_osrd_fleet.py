"""pymoo_rail.experiments.osrd_fleet (benchmarks/osrd_fleet.py's library): a row per rolling stock."""

from __future__ import annotations

from pathlib import Path

from pymoo_rail.experiments.osrd_fleet import KINDS, fleet_lines

DATA = Path(__file__).resolve().parents[1] / "data" / "osrd"


def test_every_rolling_stock_has_a_kind_and_the_optimal_run_saves_energy(tmp_path):
    assert set(KINDS) == {p.stem for p in (DATA / "rolling_stocks").glob("*.json")}
    (tmp_path / "rolling_stocks").mkdir()
    (tmp_path / "infras").symlink_to(DATA / "infras")
    (tmp_path / "rolling_stocks" / "e-tram-train.json").symlink_to(DATA / "rolling_stocks" / "e-tram-train.json")
    (line,) = fleet_lines(tmp_path)
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[6].startswith("metro, ")
    for flat_out, optimal, saving in ((cells[3], cells[4], cells[5]), (cells[8], cells[9], cells[10])):
        assert float(optimal) < float(flat_out) and saving.endswith("%") and int(saving[:-1]) > 0
