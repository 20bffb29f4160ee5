"""Shared fixtures: built-in cases and a factory for synthetic test cases."""

from __future__ import annotations

import copy
import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")

from pymoo_rail.cases import load_case  # noqa: E402
from pymoo_rail.model import case_from_dict  # noqa: E402

BASE_CASE = {
    "name": "synthetic",
    "source": "test",
    "run": {"planned_time_s": 100.0},
    "train": {
        "mass_t": 100.0, "length_m": 100.0, "max_speed_kmh": 100.0,
        "resistance": {"a": 0.0, "b": 0.0, "c": 0.0, "unit": "kN", "speed_unit": "ms"},
        "traction": {"max_force_kn": 100.0},
        "braking": {"max_force_kn": 100.0},
    },
    "line": {"length_m": 2000.0, "gradients": [[0.0, 2000.0, 0.0]], "speed_limits": [[0.0, 2000.0, 100.0]]},
}


def make_case_dict(**sections) -> dict:
    """A deep copy of the synthetic case with sections updated, e.g. ``train={"mass_t": 50.0}``."""
    data = copy.deepcopy(BASE_CASE)
    for key, value in sections.items():
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key].update(value)
        else:
            data[key] = value
    return data


def make_case(**sections):
    return case_from_dict(make_case_dict(**sections))


@pytest.fixture(scope="session")
def yizhuang():
    return load_case("yizhuang")


@pytest.fixture(scope="session")
def yizhuang_sim(yizhuang):
    from pymoo_rail.sim import Simulator

    return Simulator(yizhuang)
