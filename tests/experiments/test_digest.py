"""Kernel digests: equal inputs give equal digests, any change of value or shape changes them."""

from __future__ import annotations

import numpy as np

from pymoo_rail.experiments.digest import all_mode_programs, case_digests, digest
from pymoo_rail.sim import kernel as k


def test_digest_sees_values_and_shapes_not_dtypes():
    a = np.arange(6.0)
    assert digest(a) == digest(np.arange(6)) == digest(a.copy())
    assert digest(a) != digest(a.reshape(2, 3))
    b = a.copy()
    b[3] = np.nextafter(b[3], 10.0)
    assert digest(a) != digest(b)
    assert len(digest(a)) == 16


def test_all_mode_programs_end_at_the_line_end_and_brake_at_a_rate():
    programs = all_mode_programs(1000.0)
    assert programs.shape == (50, 6, 3)
    assert (programs[:, -1, 0] == 1000.0).all() and (np.diff(programs[:, :, 0], axis=1) >= 0).all()
    assert set(np.unique(programs[:, :, 1])) == set(range(7))
    decel = programs[:, :, 1] == k.MODE_DECEL
    assert (programs[:, :, 2][decel] >= 0.3).all() and (programs[:, :, 2][decel] <= 1.3).all()


def test_case_digests_are_reproducible():
    first, second = list(case_digests("yizhuang")), list(case_digests("yizhuang"))
    assert first == second and len(first) == 5
    assert first[0].startswith("yizhuang") and "summaries" in first[0] and "trace" in first[0]
