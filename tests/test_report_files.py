"""What of the generated reports is tracked, and its size limits (docs/architecture.md, "Generated reports").

Reports keep their numbers in markdown and CSV; figures and run records are generated and not
tracked (``benchmarks/figures.py`` rebuilds the figures).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIGURE_MAX_BYTES = 100_000
REPORT_FILE_MAX_BYTES = 150_000
REPORTS_MAX_BYTES = 1_000_000
FIGURE_SUFFIXES = (".png", ".jpg", ".jpeg", ".gif", ".svg", ".pdf")


def _tracked() -> list[Path]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: the limits apply to tracked files")
    names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [ROOT / n for n in names.decode().split("\0") if n and (ROOT / n).is_file()]


def _over(paths, limit: int, base: Path = ROOT) -> list[str]:
    return [f"{p.relative_to(base)}: {p.stat().st_size:,} bytes > {limit:,}" for p in paths if p.stat().st_size > limit]


def _generated(paths) -> list[Path]:
    """Figures and run records (``runs/*.json``) under benchmarks/ or docs/."""
    generated_dirs = (ROOT / "benchmarks", ROOT / "docs")
    return [p for p in paths if any(p.is_relative_to(d) for d in generated_dirs)
            and (p.suffix.lower() in FIGURE_SUFFIXES or (p.suffix == ".json" and p.parent.name == "runs"))]


def test_no_generated_figure_or_run_record_is_tracked():
    generated = _generated(_tracked())
    assert not generated, "generated files tracked (git rm --cached them): " + ", ".join(
        str(p.relative_to(ROOT)) for p in generated)


def test_the_generated_file_rule_catches_a_figure_and_a_run_record():
    reports = ROOT / "benchmarks" / "reports"
    paths = [reports / "x.png", ROOT / "docs" / "y.svg", reports / "s" / "runs" / "a.json", reports / "x.md",
             reports / "journeys_fronts_optimal.time.json", ROOT / "pymoo_rail" / "cases" / "data" / "line.json"]
    assert _generated(paths) == paths[:3]


def test_report_files_and_the_reports_folder_stay_within_their_budget():
    reports = [p for p in _tracked() if p.is_relative_to(ROOT / "benchmarks" / "reports")]
    others = [p for p in reports if p.suffix.lower() not in FIGURE_SUFFIXES]
    assert not _over(others, REPORT_FILE_MAX_BYTES), "\n".join(_over(others, REPORT_FILE_MAX_BYTES))
    total = sum(p.stat().st_size for p in reports)
    assert total <= REPORTS_MAX_BYTES, f"benchmarks/reports holds {total:,} bytes > {REPORTS_MAX_BYTES:,}"


def test_the_limit_catches_a_large_file(tmp_path):
    big = tmp_path / "big.png"
    big.write_bytes(b"\0" * (FIGURE_MAX_BYTES + 1))
    small = tmp_path / "small.png"
    small.write_bytes(b"\0" * 10)
    assert _over([big, small], FIGURE_MAX_BYTES, tmp_path) == [f"big.png: {FIGURE_MAX_BYTES + 1:,} bytes > 100,000"]
