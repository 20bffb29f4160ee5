"""Seeded scalable families of the suite: exact n_var, deterministic instances, pinned checksums, bad input."""

import subprocess
import sys

import numpy as np
import pytest

from pymoo_rail.journeys import front_energy, project_to_budget
from pymoo_rail.optimal import reference as ref
from pymoo_rail.suite import FAMILY_VERSION, get_problem, list_families, list_problems
from pymoo_rail.suite.families import definition, instance_name

# sha256 of the canonical definitions (pymoo_rail.suite.families.definition), family version 2.
# A change here changes what an optimiser searches: bump FAMILY_VERSION and say why in the changelog.
# The checksums leave the front version out (family version 2): a better solver keeps the instances.
PINNED = {
    ("generated-metro-bi", 10, 7): "263141e28efd",
    ("generated-metro-single", 10, 7): "4a60ebb22ea5",
    ("generated-intercity-bi", 300, 7): "90928050ed3e",
    ("generated-metro-trip", 10, 1): "35e5c9249104",
}


def test_families_and_problems_are_distinct_names():
    families = list_families()
    assert len(families) == 14 and len(set(families)) == 14
    assert {f.rsplit("-", 1)[1] for f in families} == {"bi", "single", "trip", "3obj"}
    assert not set(families) & set(list_problems())
    assert get_problem("metro-a-bi").suite_name == "metro-a-bi"  # the named problems still answer


@pytest.mark.parametrize("name", ["generated-metro-bi", "generated-high-speed-single", "generated-suburban-trip"])
@pytest.mark.parametrize("n_var", [2, 10, 37, 1000])
def test_n_var_is_exactly_what_was_asked(name, n_var):
    problem = get_problem(name, n_var=n_var, seed=3)
    assert problem.n_var == n_var == problem.xl.shape[0]
    assert problem.suite_name == instance_name(name, n_var, 3) and problem.version == FAMILY_VERSION
    assert np.all(problem.xl <= problem.xu)


@pytest.mark.parametrize("key", sorted(PINNED))
def test_checksum_pins_the_definition(key):
    name, n_var, seed = key
    problem = get_problem(name, n_var=n_var, seed=seed)
    assert problem.checksum[:12] == PINNED[key]
    assert len(problem.checksum) == 64


def test_a_new_front_version_leaves_every_checksum(monkeypatch):
    from pymoo_rail.suite import comfort, families

    names = [("generated-metro-bi", 10, 7), ("generated-metro-single", 10, 7), ("generated-metro-3obj", 10, 7)]
    before = [get_problem(*key).checksum for key in names]
    monkeypatch.setattr(families, "FRONT_VERSION", "99")
    monkeypatch.setattr(comfort, "COMFORT_FRONT_VERSION", "98")
    after = [get_problem(*key) for key in names]
    assert [p.checksum for p in after] == before
    assert [p.front_version for p in after] == ["99", "99", "99+comfort98"]


def test_checksum_changes_with_every_part_of_the_identity():
    base = get_problem("generated-metro-bi", n_var=10, seed=7).checksum
    others = [get_problem("generated-metro-bi", n_var=11, seed=7), get_problem("generated-metro-bi", n_var=10, seed=8),
              get_problem("generated-suburban-bi", n_var=10, seed=7),
              get_problem("generated-metro-single", n_var=10, seed=7)]
    assert len({base, *(p.checksum for p in others)}) == 5


def test_same_instance_in_a_fresh_process_whatever_the_global_random_state():
    code = ("import numpy as np; np.random.seed(99); from pymoo_rail.suite import get_problem; "
            "p = get_problem('generated-suburban-bi', n_var=40, seed=5); print(p.checksum)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    here = get_problem("generated-suburban-bi", n_var=40, seed=5)
    assert out == here.checksum
    again = get_problem("generated-suburban-bi", n_var=40, seed=5)
    X = np.random.default_rng(0).uniform(here.xl, here.xu, (8, here.n_var))
    a, b = (p.evaluate(X, return_as_dictionary=True) for p in (here, again))
    assert np.array_equal(a["F"], b["F"]) and np.array_equal(a["G"], b["G"])


def test_definition_names_what_an_optimiser_searches():
    problem = get_problem("generated-metro-single", n_var=12, seed=2)
    d = definition(problem, "generated-metro-single", 2)
    assert d["case_hash"] == ref.case_hash(problem.case)
    # the front is the solver's, versioned on its own: not part of what defines the instance
    assert "front_version" not in d and problem.front_version == ref.FRONT_VERSION
    assert d["encoding"] == "paced_speed_codes" and len(d["sections_m"]) == 12 and len(d["xl"]) == 12
    assert d["objectives"] == ["energy"] and d["time_tolerance_s"] is not None


def test_bi_instances_are_on_the_certified_fronts_window():
    problem = get_problem("generated-intercity-bi", n_var=50, seed=2)
    assert problem.objectives == ("energy", "running_time")
    assert problem.time_window_s == problem.bi_window_s
    # the upper bounds are the flat-out run: 0.5 % faster than the window allows, so infeasible by that much
    out = problem.evaluate(problem.xu[None, :], return_as_dictionary=True)
    assert out["F"][0, 1] == pytest.approx(problem.min_running_time_s, rel=1e-3)
    assert out["G"][0, -1] == pytest.approx(problem.time_window_s[0] - out["F"][0, 1]) and out["G"][0, -1] > 0
    assert np.all(out["G"][0, :-1] <= 0)


@pytest.mark.parametrize("kwargs, match", [
    (dict(n_var=1), r"n_var = 1: must be an integer in \[2, 1000\]"),
    (dict(n_var=1001), "n_var = 1001"),
    (dict(n_var=True), "n_var = True"),
    (dict(n_var=10.0), r"n_var = 10\.0"),
    (dict(seed=-1), "seed = -1: must be an integer >= 0"),
    (dict(seed="7"), "seed = '7'"),
    (dict(encoding="switching_points"), "defined by n_var and seed alone; encoding"),
])
def test_bad_instance_arguments_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        get_problem("generated-metro-bi", **kwargs)


def test_unknown_names_and_family_arguments_on_named_problems():
    with pytest.raises(ValueError, match="generated-metro-bi"):
        get_problem("generated-tram-bi", n_var=10)
    with pytest.raises(ValueError, match="n_var = 10: problem 'yizhuang-bi' is not a family"):
        get_problem("yizhuang-bi", n_var=10)
    with pytest.raises(ValueError, match="seed = 3: problem 'yizhuang-bi' is not a family"):
        get_problem("yizhuang-bi", seed=3)


def test_a_trip_optimum_is_exact_and_shorter_trips_are_its_first_sections():
    short, trip = (get_problem("generated-metro-trip", n_var=n, seed=4) for n in (5, 40))
    assert np.array_equal(short.sections, trip.sections[:5]) and len(set(trip.sections)) > 1
    assert all(c.initial_speed_ms == 0.0 == c.final_speed_ms for c in trip.pool)
    times, energy = trip.optimum
    assert times.sum() == pytest.approx(trip.total_time_s) and trip.pareto_front()[0, 0] == energy
    # no split on the budget costs less: random splits projected onto it, and moves of one second
    rng = np.random.default_rng(0)
    X = project_to_budget(rng.uniform(trip.xl, trip.xu, (200, trip.n_var)), trip.xl, trip.xu, trip.total_time_s)
    out = trip.evaluate(X, return_as_dictionary=True)
    assert np.all(np.abs(out["H"]) < 1e-6) and np.all(out["F"][:, 0] >= energy - 1e-9)
    for i, j in rng.integers(0, trip.n_var, (50, 2)):
        moved = times.copy()
        moved[i] += 1.0
        moved[j] -= 1.0
        if i != j and trip.xl[j] <= moved[j] and moved[i] <= trip.xu[i]:
            assert trip.evaluate(moved[None, :])[0][0, 0] >= energy - 1e-9
    # the section curves are convex and decreasing: the slowest split in the box costs least
    slowest = sum(front_energy(f, f["running_time_s"].iloc[-1]) for f in trip.fronts)
    assert slowest < energy < trip.hv_reference_point()[0]


def test_a_line_the_exact_solver_gives_up_on_has_no_front_and_says_so(monkeypatch):
    problem = get_problem("generated-intercity-bi", n_var=10, seed=7)

    def gives_up(*args, **kwargs):
        raise RuntimeError("running_time_s = 1753.7: the closest optimum takes 1745.10 s; refine the grid")

    monkeypatch.setattr(ref, "certified_front", gives_up)
    with pytest.raises(ref.NoExactFrontError, match="generated-intercity-bi-n10-s7: the exact solver gave up"):
        problem.pareto_front()
    with pytest.raises(ref.NoExactFrontError, match="refine the grid"):
        problem.hv_reference_point()


def test_a_study_file_names_an_instance_by_family_n_var_and_seed():
    from pymoo_rail.experiments import problem as problem_spec
    from pymoo_rail.experiments.registry import build_problem
    from pymoo_rail.experiments.spec import StudyError

    built = build_problem(problem_spec("suite_family", family="generated-metro-bi", n_var=20, seed=3))
    assert built.checksum == get_problem("generated-metro-bi", n_var=20, seed=3).checksum
    with pytest.raises(StudyError, match="n_var = 1001"):
        build_problem(problem_spec("suite_family", family="generated-metro-bi", n_var=1001, seed=3))
    # one way to name an instance: rail_suite takes the named problems only, and says which entry to use
    with pytest.raises(StudyError, match='problem = "suite_family"'):
        build_problem(problem_spec("rail_suite", suite_problem="generated-metro-bi"))
