"""The real files the tests and the package read (TTOBench, OSRD) sit with their licence, and each
folder's README names where every file came from."""

from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OSRD = ROOT / "tests" / "data" / "osrd"
TTOBENCH = ROOT / "tests" / "data" / "ttobench"
PACKAGED = ROOT / "pymoo_rail" / "cases" / "data"


def test_osrd_files_carry_the_lgpl_and_each_is_named_in_the_readme():
    assert "GNU LESSER GENERAL PUBLIC LICENSE" in (OSRD / "LICENSE-LGPL-3.0.txt").read_text()
    assert "GNU GENERAL PUBLIC LICENSE" in (OSRD / "LICENSE-GPL-3.0.txt").read_text()
    readme = (OSRD / "README.md").read_text()
    assert "LGPL-3.0" in readme and "The OSRD Contributors" in readme
    files = sorted(OSRD.rglob("*.json"))
    assert len(files) == 16  # 11 rolling stocks, 4 infrastructures, 1 pathfinding result
    for path in files:
        assert path.name in readme or f"{path.parent.name}/*.json" in readme, path


def test_ttobench_files_carry_the_bsd_licence():
    notice = "Copyright (c) 2022, Dimitris Kouzoupis"
    for folder in (TTOBENCH, PACKAGED):
        licence = next(folder.glob("*LICENSE"))
        assert notice in licence.read_text() and "BSD 2-Clause" in licence.read_text()
    readme = (TTOBENCH / "README.md").read_text()
    for path in sorted(TTOBENCH.rglob("*.json")):
        # every file is TTOBench's own: its metadata names the library, and the README its origin
        meta = json.loads(path.read_text())["metadata"]
        assert "TTOBench" in meta.get("library version", ""), path
        assert path.parent.name in ("tracks", "trains", "journeys") or path.name in readme, path
    for path in sorted(PACKAGED.glob("*.json")):  # shipped in the wheel with TTOBENCH_LICENSE
        assert "BSD 2-Clause License" in json.loads(path.read_text())["metadata"]["license"], path
