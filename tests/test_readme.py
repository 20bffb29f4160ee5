"""Every snippet of the README and of docs/*.md runs, and every command line they show parses.

A docs page's Python blocks run in order in one namespace (a later block may use what an earlier
one defined), in a temporary folder. A block that takes more than a few CPU seconds is marked by
the line ``<!-- snippet: slow -->`` right above its fence: it is left out of the default run and
executed, with all the page's blocks, by ``python -m pytest -m slow tests/test_readme.py``.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from pymoo_rail.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = [README, *sorted(DOCS.glob("*.md"))]
MARKS = ("slow",)
_BLOCK = re.compile(r"(?:<!-- snippet: (?P<mark>\S+) -->\n)?^```(?P<lang>\w+)\n(?P<code>.*?)^```", re.S | re.M)


def snippets(page: Path, language: str = "python") -> list[tuple[str | None, int, str]]:
    """(mark, line of the first code line, code) of every ``language`` block of a page."""
    text = page.read_text()
    return [(m.group("mark"), text.count("\n", 0, m.start("code")) + 1, m.group("code"))
            for m in _BLOCK.finditer(text) if m.group("lang") == language]


def blocks(language: str) -> list[str]:
    return [code for _, _, code in snippets(README, language)]


def run_page(page: Path, with_slow: bool) -> int:
    """Run a page's Python blocks in order in one namespace; returns how many ran."""
    namespace = {"__name__": "__docs__"}
    ran = 0
    for mark, line, code in snippets(page):
        if mark == "slow" and not with_slow:
            continue
        # padded so that a traceback names the line of the page
        exec(compile("\n" * (line - 1) + code, str(page.relative_to(ROOT)), "exec"), namespace)
        ran += 1
    return ran


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_readme_python_snippet_runs_on_its_own(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # snippets write files (run.csv)
    exec(compile(blocks("python")[index], f"README.md python block {index}", "exec"), {"__name__": "__readme__"})


DOC_PAGES = [p for p in PAGES[1:] if snippets(p)]


@pytest.mark.parametrize("page", [p for p in DOC_PAGES if any(m is None for m, _, _ in snippets(p))],
                         ids=lambda p: p.name)
def test_docs_python_snippets_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # snippets write files (out/...)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    assert run_page(page, with_slow=False) > 0


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in DOC_PAGES if any(m == "slow" for m, _, _ in snippets(p))],
                         ids=lambda p: p.name)
def test_docs_slow_python_snippets_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    assert run_page(page, with_slow=True) == len(snippets(page))


def test_every_docs_snippet_compiles():
    # the slow ones too: a syntax error shows without running them
    for page in PAGES:
        for _, line, code in snippets(page):
            compile("\n" * (line - 1) + code, str(page.relative_to(ROOT)), "exec")


def test_snippet_marks_are_known():
    marks = {(page.name, mark) for page in PAGES for lang in ("python", "bash")
             for mark, _, _ in snippets(page, lang) if mark is not None}
    assert {(name, mark) for name, mark in marks if mark not in MARKS} == set()


def test_readme_and_docs_command_lines_parse():
    parser = build_parser()
    commands = []
    for page in PAGES:
        for _, _, block in snippets(page, "bash"):
            for line in block.replace("\\\n", " ").splitlines():  # a continued line is one command
                line = line.split("#")[0].strip()
                if line.startswith("pymoo-rail ") or " pymoo-rail " in line:
                    commands.append((page.name, shlex.split(line[line.index("pymoo-rail "):].split("&&")[0])[1:]))
    assert any(name == README.name for name, _ in commands)
    for name, argv in commands:
        try:
            parser.parse_args(argv)
        except SystemExit:  # argparse exits on an unknown option or command
            pytest.fail(f"{name}: pymoo-rail {' '.join(argv)} does not parse")


def test_readme_and_docs_stay_inside_the_repository():
    texts = {page.relative_to(ROOT).as_posix(): page.read_text() for page in PAGES}
    pattern = re.compile(r"\.\./shared|DESIGN\.md|shared/seeds|\bseeds? 00\d|\bthe lead\b|issue \d|"
                         r"still needs a decision|done-when", re.I)
    leaks = [(name, m.group(0)) for name, text in texts.items() for m in pattern.finditer(text)]
    assert leaks == []
