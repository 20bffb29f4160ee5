"""Every TTOBench field: TTOBench's own format descriptions, the importer and docs/ttobench.md agree."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from pymoo_rail.cases.ttobench import known_fields

ROOT = Path(__file__).resolve().parents[2]
RELEASE = ROOT / "tests" / "data" / "ttobench"
DOC = (ROOT / "docs" / "ttobench.md").read_text(encoding="utf-8")
# bullets of the journey README that name the two kinds of timing point, not fields
NOT_FIELDS = {"stopping points", "passing points"}


def readme_fields(kind: str) -> tuple[set[str], set[str]]:
    """Top-level fields and sub-fields (indented bullets) named in TTOBench's README of ``kind``."""
    text = (RELEASE / f"{kind}s" / "README.md").read_text(encoding="utf-8")
    top = set(re.findall(r"^- `([^`]+)`", text, re.M)) - NOT_FIELDS
    sub = set(re.findall(r"^  +- `([^`]+)`", text, re.M))
    return top, sub


def doc_table(kind: str) -> str:
    """The rows of the docs table of one file kind ("Track", "Train", "Journey")."""
    start = DOC.index(f"**{kind} files**")
    end = DOC.index("\n\n", DOC.index("|---", start))
    return DOC[start:end]


@pytest.mark.parametrize("kind", ["track", "train", "journey"])
def test_every_field_ttobench_documents_is_known_to_the_importer_and_in_the_docs(kind):
    top, sub = readme_fields(kind)
    assert top, f"no fields found in the {kind} README"
    known = set(known_fields()[kind])
    assert top <= known, f"fields TTOBench documents that the importer refuses: {sorted(top - known)}"
    table = doc_table(kind.capitalize())
    first_column = {name for row in table.splitlines() if row.startswith("| `")
                    for name in re.findall(r"`([^`]+)`", row.split("|")[1])}
    assert known <= first_column, f"importer fields missing from docs/ttobench.md: {sorted(known - first_column)}"
    nested = {name for key, names in known_fields().items() if key.startswith(kind + ".") for name in names}
    assert sub <= nested, f"sub-fields TTOBench documents that the importer refuses: {sorted(sub - nested)}"
    for name in nested:
        assert f"`{name}`" in table, f"{name} is not in the {kind} table of docs/ttobench.md"


def test_the_efficiency_fields_ttobench_has_not_documented_yet_are_in_the_docs():
    # the train README says "documentation of vehicle efficiency is pending"; the release uses them
    top, _ = readme_fields("train")
    extra = set(known_fields()["train"]) - top
    assert extra == {"efficiency traction", "efficiency reg brake"}
    assert "documentation of vehicle efficiency is pending" in (RELEASE / "trains" / "README.md").read_text()
