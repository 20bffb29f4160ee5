"""The encodings compared by ``benchmarks/encodings.py``."""

from __future__ import annotations

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.encodings import DE_ENCODINGS, de_encodings


def test_de_compares_the_four_encodings_and_hold_brake():
    encodings = de_encodings(load_case("yizhuang"))
    assert list(encodings)[:4] == list(DE_ENCODINGS)
    assert "hold_brake" in encodings["switching points, hold_brake"]["regimes"]
    assert "hold" not in encodings["switching points, hold_brake"]["regimes"]
