"""Every snippet of the README runs, and every command line it shows parses."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from pymoo_rail.cli import build_parser

README = Path(__file__).resolve().parents[1] / "README.md"
DOCS = Path(__file__).resolve().parents[1] / "docs"


def blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README.read_text(), flags=re.S)


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_readme_python_snippet_runs_on_its_own(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # snippets write files (run.csv)
    exec(compile(blocks("python")[index], f"README.md python block {index}", "exec"), {"__name__": "__readme__"})


def test_readme_command_lines_parse():
    parser = build_parser()
    commands = []
    for block in blocks("bash"):
        for line in block.splitlines():
            line = line.split("#")[0].strip()
            if "pymoo-rail " in line:
                commands.append(shlex.split(line[line.index("pymoo-rail "):].split("&&")[0])[1:])
    assert commands
    for argv in commands:
        parser.parse_args(argv)  # exits (SystemExit) on an unknown option or command


def test_readme_and_docs_stay_inside_the_repository():
    texts = {README.name: README.read_text()} | {f"docs/{p.name}": p.read_text() for p in DOCS.glob("*.md")}
    pattern = re.compile(r"\.\./shared|DESIGN\.md|shared/seeds|\bseeds? 00\d|\bthe lead\b|issue \d|"
                         r"still needs a decision|done-when", re.I)
    leaks = [(name, m.group(0)) for name, text in texts.items() for m in pattern.finditer(text)]
    assert leaks == []
