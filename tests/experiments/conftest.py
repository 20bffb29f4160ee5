"""The small study of issue 5, run once per session on the local pool."""

from __future__ import annotations

import pytest

from pymoo_rail.experiments import run_study
from tests.experiments.studies import small_study


@pytest.fixture(scope="session")
def pool_study_dir(tmp_path_factory):
    """The small study (3 problems x 3 algorithms x 5 seeds) run on a 2-process local pool."""
    directory = tmp_path_factory.mktemp("pool")
    report = run_study(small_study(), directory, workers=2, progress=False)
    assert report.n_finished == 45 and not report.failures, str(report)
    return directory
