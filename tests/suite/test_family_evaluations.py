"""Frozen definitions of the families: shipped reference evaluations recomputed, fronts from the shipped file."""

import json

import numpy as np
import pytest

from pymoo_rail.optimal import reference as ref
from pymoo_rail.suite import get_problem
from pymoo_rail.suite.evaluations import (
    REFERENCE_DIMENSIONS,
    REFERENCE_PATH,
    check_reference_evaluations,
    compute_reference_evaluations,
)
from pymoo_rail.suite.families import FAMILY_VERSION, list_families


def test_shipped_reference_evaluations_are_recomputed():
    data = json.loads(REFERENCE_PATH.read_text())
    assert data["family_version"] == FAMILY_VERSION
    assert {(r["family"], r["n_var"]) for r in data["records"]} == {
        (f, n) for f in list_families() for n in REFERENCE_DIMENSIONS}
    G = np.vstack([np.asarray(r["G"]).max(axis=1) for r in data["records"] if r["family"].endswith("-bi")])
    assert (G > 0).any() and (G <= 0).any()  # the vectors test the constraints, not only the objectives
    table = check_reference_evaluations()
    assert table["checksum_ok"].all(), table[~table["checksum_ok"]]
    assert table["ok"].all(), table[~table["ok"]]


def test_a_changed_value_or_definition_is_caught(tmp_path):
    data = compute_reference_evaluations(families=["generated-metro-bi"], dimensions=(10,))
    data["records"][0]["F"][0][0] += 1e-3
    path = tmp_path / "moved.json"
    path.write_text(json.dumps(data))
    table = check_reference_evaluations(path)
    assert not table["ok"][0] and table["checksum_ok"][0]
    assert table["max_abs_dev_F"][0] == pytest.approx(1e-3)
    data["records"][0]["F"][0][0] -= 1e-3
    data["records"][0]["checksum"] = "0" * 64
    path.write_text(json.dumps(data))
    table = check_reference_evaluations(path)
    assert not table["ok"][0] and not table["checksum_ok"][0] and table["max_abs_dev_F"][0] == 0.0


def test_every_dimension_of_an_instance_has_the_same_certified_front():
    """The front is the train's on the line, whatever the sections: metro seed 1 ships its front."""
    small, large = (get_problem("generated-metro-bi", n_var=n, seed=1) for n in (10, 1000))
    path = ref.find_front(small.case)
    assert path is not None and path.parent == ref.SHIPPED_DIR
    pf = small.pareto_front()
    assert np.array_equal(pf, large.pareto_front())
    assert np.all(np.diff(pf[:, 0]) > 0) and np.all(np.diff(pf[:, 1]) < 0)  # sorted by energy: time falls
    lo, hi = small.time_window_s
    assert pf[0, 1] == pytest.approx(hi, abs=0.5) and pf[-1, 1] == pytest.approx(lo, abs=0.5)
    np.testing.assert_array_equal(small.ideal_point(), pf.min(axis=0))
    np.testing.assert_array_equal(small.nadir_point(), pf.max(axis=0))
    ref_point = small.hv_reference_point()
    span = small.nadir_point() - small.ideal_point()
    np.testing.assert_allclose(ref_point, small.nadir_point() + 0.1 * span, rtol=1e-6)


def test_the_single_form_optimum_lies_on_the_front_at_the_plan():
    single = get_problem("generated-metro-single", n_var=10, seed=1)
    front = single.certified_front()
    optimum = single.pareto_front()
    assert optimum.shape == (1, 1)
    tolerance = single.time_tolerance_s
    energy, _ = front.energy_at(single.case.planned_time_s + tolerance)
    assert optimum[0, 0] == pytest.approx(energy[0])  # the slow end of the punctuality window: a node
    # an optimiser's on-time runs never beat it by more than the certificate
    X = np.random.default_rng(2).uniform(single.xl, single.xu, (30, single.n_var))
    out = single.evaluate(X, return_as_dictionary=True)
    feasible = (out["G"] <= 0).all(axis=1)
    _, below = front.below_certificate(out["running_time_s"][feasible], out["F"][feasible, 0])
    assert feasible.sum() > 20 and not below.any()
    assert single.hv_reference_point()[0] > optimum[0, 0]


@pytest.mark.slow
def test_a_front_is_computed_on_demand_once_then_read_from_the_disk_cache(tmp_path, monkeypatch):
    """About 20 s of CPU: the exact solver on one metro line (seed 2 ships no front)."""
    from pymoo_rail.optimal.reference import store

    monkeypatch.setenv(ref.CACHE_ENV, str(tmp_path))
    ref.forget_fronts()
    small = get_problem("generated-metro-bi", n_var=20, seed=2)
    assert ref.find_front(small.case) is None
    pf = small.pareto_front()
    path = ref.find_front(small.case)
    assert path.parent == tmp_path / "fronts" and path.name.startswith("generated-metro-2-")
    assert ref.CertifiedFront.read_csv(path).case_hash == ref.case_hash(small.case)
    ref.forget_fronts()

    def no_solver(*args, **kwargs):
        raise AssertionError("the front was solved again instead of read from the cache")

    monkeypatch.setattr(store, "compute_front", no_solver)
    large = get_problem("generated-metro-bi", n_var=500, seed=2)
    np.testing.assert_allclose(large.pareto_front(), pf, rtol=1e-6)  # the file keeps 9 significant digits
    ref.forget_fronts()
