"""Studies at scale: problems x algorithms x seeds, on a local pool or a Dask cluster.

>>> from pymoo_rail.experiments import Study, problem, algorithm, run_study, load_results
>>> study = Study("zdt", problems=[problem("zdt1"), problem("zdt2")],
...               algorithms=[algorithm("nsga2", pop_size=40), algorithm("moead", pop_size=40)],
...               seeds=5, budget={"n_gen": 100}, baseline="nsga2")
>>> report = run_study(study, "out/zdt", workers=2)                  # doctest: +SKIP
>>> results = load_results("out/zdt")                                # doctest: +SKIP

See ``docs/experiments.md``.
"""

from pymoo_rail.experiments.registry import (
    ALGORITHMS,
    PROBLEMS,
    UntrustedCodeError,
    algorithm_names,
    build_algorithm,
    build_problem,
    problem_names,
)
from pymoo_rail.experiments.fronts import (
    best_of_seeds,
    best_run,
    choose_member,
    distinct_front,
    distinct_index,
    punctual_member,
)
from pymoo_rail.experiments.results import indicator_columns, load_records, load_results, records_frame
from pymoo_rail.experiments.runner import StudyReport, execute_run, run_study
from pymoo_rail.experiments.spec import (
    AlgorithmSpec,
    Budget,
    ProblemSpec,
    RunSpec,
    Study,
    StudyError,
    algorithm,
    problem,
    tang2020_nsga2,
)
from pymoo_rail.experiments.store import ResultStore
from pymoo_rail.experiments.study_file import read_study, study_to_toml, write_study

__all__ = ["Study", "ProblemSpec", "AlgorithmSpec", "Budget", "RunSpec", "StudyError", "problem", "algorithm",
           "run_study", "execute_run", "StudyReport", "load_results", "load_records", "records_frame",
           "indicator_columns", "read_study", "write_study", "study_to_toml", "ResultStore", "PROBLEMS",
           "ALGORITHMS", "problem_names", "algorithm_names", "build_problem", "build_algorithm", "distinct_front",
           "distinct_index", "choose_member", "punctual_member", "tang2020_nsga2", "best_of_seeds", "best_run",
           "UntrustedCodeError"]
