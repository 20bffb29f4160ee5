"""The EMU study of seed 003 (section 4.2) on `wuguang-crh3`: golden-ratio NSGA-II fronts coast
through both neutral sections, stay under every limit over the train length and stop at the
platform; the neutral-section genes never change; the benchmark script runs end to end."""

from __future__ import annotations

import csv
import dataclasses

import numpy as np
import pytest
from pymoo.optimize import minimize

from pymoo_rail.algorithms import GoldenRatioNSGA2
from pymoo_rail.cases import load_case
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.checks import check_run, limit_under_train_ms

# seed 003, 4.2: the two neutral sections (m), planned time and margin, table 2 limits
NEUTRAL_M = ((16177.0, 16819.0), (40079.0, 40705.0))
PLANNED_S, MARGIN_S = 1050.0, 60.0
STOP_TOLERANCE_M = 0.25


class RecordingProblem(SpeedProfileProblem):
    """The speed-profile problem that keeps every decision vector it evaluates."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.seen = []

    def _evaluate(self, x, out, *args, **kwargs):
        self.seen.append(np.array(x, copy=True))
        super()._evaluate(x, out, *args, **kwargs)


@pytest.fixture(scope="module")
def wuguang():
    return load_case("wuguang-crh3")


def neutral_cells(position_m: np.ndarray) -> np.ndarray:
    """Cells (starting at each node but the last) that touch one of the seed's neutral sections."""
    touch = np.zeros(position_m.shape[0] - 1, dtype=bool)
    for start, end in NEUTRAL_M:
        touch |= (position_m[:-1] < end) & (position_m[1:] > start)
    return touch


@pytest.fixture(scope="module")
def grnsga2_run(wuguang):
    problem = RecordingProblem(wuguang, objectives=("energy", "running_time"), time_tolerance_s=wuguang.time_margin_s)
    mask = problem.encoding.fixed()
    # start from fast programs (60-100 % of each section's range) so that a short run has feasible members
    rng = np.random.default_rng(7)
    X0 = problem.xl + (problem.xu - problem.xl) * rng.uniform(0.6, 1.0, (20, problem.n_var))
    algorithm = GoldenRatioNSGA2(pop_size=20, local_size=6, fixed_genes=mask, sampling=X0)
    res = minimize(problem, algorithm, ("n_gen", 12), seed=3)
    return problem, mask, X0, res


def test_case_is_the_seed_run(wuguang):
    assert wuguang.line.length_m == 47646.0
    assert wuguang.planned_time_s == PLANNED_S and wuguang.time_margin_s == MARGIN_S
    assert tuple(map(tuple, wuguang.line.neutral_sections)) == NEUTRAL_M


def test_fixed_genes_are_the_two_neutral_sections(grnsga2_run):
    problem, mask, _, _ = grnsga2_run
    b = problem.encoding.boundaries_m
    sections = [(b[i], b[i + 1]) for i in np.flatnonzero(mask)]
    assert sections == [NEUTRAL_M[0], NEUTRAL_M[1]]


def test_fixed_genes_never_change(grnsga2_run):
    problem, mask, X0, res = grnsga2_run
    X = np.vstack(problem.seen)
    assert len(X) > 12 * 20  # every generation's offspring and local-search points are in there
    assert np.all(X[:, mask] == X0[0, mask])
    assert np.all(X[:, ~mask].std(axis=0) > 0.1)  # while the free genes did move (km/h)
    assert np.all(res.X[:, mask] == X0[0, mask])


def test_front_coasts_through_neutral_sections_stays_under_limits_and_stops(grnsga2_run, wuguang):
    problem, _, _, res = grnsga2_run
    feasible = res.CV[:, 0] <= 0
    assert feasible.sum() >= 5
    for x, f in zip(res.X[feasible], res.F[feasible]):
        traj = problem.trajectory(x)
        cells = neutral_cells(traj.position_m)
        assert cells.sum() > 2 * 100  # both sections, > 600 m each, are in the trace
        assert traj.force_n[:-1][cells].max() <= 0.0  # no traction anywhere in a neutral section
        assert traj.summary["neutral_traction_j"] == 0.0
        assert traj.summary["limit_excess_ms"] <= 0.0
        excess = traj.speed_ms - limit_under_train_ms(traj.position_m, wuguang.line, wuguang.train)
        assert excess.max() <= 1e-9
        assert check_run(traj, wuguang).passes(STOP_TOLERANCE_M, 1e-9)
        assert traj.stop_error_m <= STOP_TOLERANCE_M
        assert abs(traj.running_time_s - PLANNED_S) <= MARGIN_S
        assert traj.running_time_s == pytest.approx(f[1], abs=1e-9)
        assert traj.energy.net_kwh == pytest.approx(f[0], abs=1e-9)


def test_no_traction_in_neutral_sections_even_when_the_program_asks_for_it(wuguang):
    """The checks above are not vacuous: a program that wants 300 km/h everywhere pulls in the
    neutral sections on a line without them, and never on the real line."""
    problem = SpeedProfileProblem(wuguang, objectives=("energy", "running_time"))
    program = problem.encoding.programs(problem.xu[None, :] * 0 + 300.0)[0]
    bare = dataclasses.replace(wuguang, line=dataclasses.replace(wuguang.line, neutral_sections=()))
    pulled = Simulator(bare).run(program)
    coasted = Simulator(wuguang).run(program)
    x = pulled.position_m
    for start, end in NEUTRAL_M:  # N: without the sections the train pulls hard in each of them
        assert pulled.force_n[:-1][(x[:-1] < end) & (x[1:] > start)].max() > 50e3
    assert coasted.force_n[:-1][neutral_cells(coasted.position_m)].max() <= 0.0
    assert coasted.summary["neutral_traction_j"] == 0.0
    # the package's run check sees the pull in the sections of the real line
    assert check_run(pulled, wuguang).neutral_max_force_n > 50e3 and not check_run(pulled, wuguang).passes()
    assert check_run(coasted, wuguang).neutral_max_force_n <= 0.0
    # the coasted run loses speed in each section and so takes longer
    assert coasted.running_time_s > pulled.running_time_s


def test_independent_limit_check_catches_an_overspeed(wuguang):
    """The limit check over the train length flags a speed above the 80 km/h exit zone that
    the head has already left but the tail has not."""
    position = np.array([1000.0, 2000.0, 2100.0, 2300.0])
    speed_ms = np.array([80.0, 80.0, 80.5, 81.0]) / 3.6
    excess = speed_ms - limit_under_train_ms(position, wuguang.line, wuguang.train)
    # at 2100 m the tail (201.4 m behind) is still in the 80 km/h zone; at 2300 m it has left it
    assert excess[2] > 0 and excess[3] < 0


@pytest.mark.slow
def test_reduced_study_end_to_end(tmp_path):
    """The benchmark script with a reduced study (3 seeds, 3000 evaluations, population 30) on
    2 worker processes: every front member passes the checks and the report is written."""
    from benchmarks import emu_wuguang  # every algorithm is a registry name: workers need no sys.path

    code = emu_wuguang.main(["--seeds", "3", "--budget", "3000", "--pop-size", "30", "--local-size", "6",
                             "--encoding-seeds", "2", "--encoding-budget", "1000", "--workers", "2",
                             "--work", str(tmp_path / "work"), "--out", str(tmp_path / "report"),
                             "--no-progress", "--no-exact"])
    assert code == 0  # 0 only when every member of every front passed the verification
    report = (tmp_path / "report" / "emu_wuguang.md").read_text()
    for part in ("Table 4", "table 5", "fig. 12", "rank-sum", "All ", "members pass: yes"):
        assert part in report
    for name in ("fronts", "fronts_overlay", "fronts_zoom", "profile", "box_hv"):
        assert (tmp_path / "report" / f"emu_wuguang_{name}.png").stat().st_size > 10_000
    with open(tmp_path / "report" / "emu_wuguang_runs.csv") as fh:
        rows = list(csv.DictReader(fh))
    main = [r for r in rows if r["study"] == "main"]
    # 2 encodings (speed codes, switching points) x 2 algorithms x 3 seeds
    assert len(main) == 12 and {r["algorithm"] for r in main} == {"NSGA-II", "GR-NSGA-II"}
    assert len([r for r in rows if r["study"] == "encodings"]) == 3 * 2 * 2
    for r in main:
        assert 3000 <= int(r["n_eval"]) < 3000 + 30 + 9 + 1  # at most one generation (30 + 1.5 * 6) over
        assert r["verified"] == "True" and r["fixed_genes_ok"] == "True"
        assert float(r["t_min"]) >= PLANNED_S - MARGIN_S and float(r["t_max"]) <= PLANNED_S + MARGIN_S
