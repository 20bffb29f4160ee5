"""The example study of docs/experiments.md, saved as a script, runs and gives real indicators (issue 34)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
PAGE = REPO / "docs" / "experiments.md"


def example_script() -> str:
    """The first Python block of the page that runs a study under the ``__main__`` guard."""
    blocks = re.findall(r"^```python\n(.*?)^```", PAGE.read_text(encoding="utf-8"), re.S | re.M)
    return next(b for b in blocks if 'if __name__ == "__main__":' in b and "run_study(" in b)


def test_the_example_keeps_the_guard_and_the_running_time_window():
    script = example_script()
    assert 'time_window_s="default"' in script
    guard = script.index('if __name__ == "__main__":')
    assert "run_study(" not in script[:guard]  # a spawned pool worker imports the script: nothing runs then


@pytest.mark.slow
def test_the_example_study_runs_as_a_script_with_igd_gd_hv_on_yizhuang(tmp_path):
    from pymoo_rail.experiments import load_results, stats

    script = tmp_path / "rail_study.py"
    script.write_text(example_script(), encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "30 runs: 0 already stored, 30 run now, 0 failed" in done.stdout
    results = load_results(tmp_path / "out" / "rail")
    yizhuang = results[results["problem"] == "yizhuang"]
    assert len(yizhuang) == 15
    for column in ("igd", "gd", "hv"):
        assert np.all(np.isfinite(yizhuang[column].to_numpy(float))), column
    table = stats.indicator_table(results, "igd", baseline="nsga2")
    assert set(table.index) == {"zdt1", "yizhuang"}
    assert not table.apply(lambda col: col.str.startswith("n/a")).any().any()
