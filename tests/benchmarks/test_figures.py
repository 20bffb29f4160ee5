"""benchmarks/figures.py: every script that draws a figure is listed, and the listing says what needs a rerun."""

from __future__ import annotations

import re
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def test_every_script_that_saves_a_figure_is_listed():
    from benchmarks import figures

    drawing = {p.stem for p in BENCHMARKS.glob("*.py") if re.search(r"\bsave_figure\(", p.read_text())}
    listed = {entry.script for entry in figures.FIGURES}
    assert drawing and drawing <= listed, f"scripts drawing figures not in benchmarks/figures.py: {drawing - listed}"
    assert all((BENCHMARKS / f"{name}.py").is_file() for name in listed)


def test_the_listing_names_a_rerun_for_what_committed_data_cannot_rebuild(capsys, monkeypatch, tmp_path):
    from benchmarks import figures

    monkeypatch.setattr(figures, "ROOT", tmp_path)  # no study records anywhere
    assert figures.main(["--list"]) == 0
    out = capsys.readouterr().out
    assert "moabc_zdt: would rebuild moabc_zdt_igd.png" in out
    assert "optimal: needs a rerun (`python benchmarks/optimal.py`): optimal_front.png" in out
    for entry in figures.FIGURES:
        assert all(name in out for name in entry.figures), entry.script
