"""The size limits of committed reports and figures (docs/architecture.md, "Generated reports")."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIGURE_MAX_BYTES = 100_000
REPORT_FILE_MAX_BYTES = 150_000
REPORTS_MAX_BYTES = 3_500_000
FIGURE_SUFFIXES = (".png", ".jpg", ".jpeg", ".gif", ".svg", ".pdf")


def _tracked() -> list[Path]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: the limits apply to tracked files")
    names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [ROOT / n for n in names.decode().split("\0") if n and (ROOT / n).is_file()]


def _over(paths, limit: int, base: Path = ROOT) -> list[str]:
    return [f"{p.relative_to(base)}: {p.stat().st_size:,} bytes > {limit:,}" for p in paths if p.stat().st_size > limit]


def test_every_tracked_figure_is_small():
    figures = [p for p in _tracked() if p.suffix.lower() in FIGURE_SUFFIXES]
    assert figures, "no tracked figure found: the check would be vacuous"
    assert not _over(figures, FIGURE_MAX_BYTES), "\n".join(_over(figures, FIGURE_MAX_BYTES))


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
