"""Every snippet of the README and of docs/*.md runs, and every command line they show parses.

A docs page's Python blocks run in order as one script (``python page.py`` in a fresh process, so
``__name__ == "__main__"`` and a study's process pool behave as in a user's own script), in a
temporary folder. Marks, an HTML comment on the line right above a block's fence, with a reason:

- ``<!-- snippet: slow: <reason> -->``: takes more than a few CPU seconds; left out of the default
  run and executed, with all the page's blocks, by ``python -m pytest -m slow tests/test_readme.py``.
- ``<!-- snippet: skip: <reason> -->``: never run (e.g. it needs a Dask cluster); still compiled.
- ``<!-- output -->`` (or ``<!-- output: within 1 % -->``) above a ``text`` block right after a
  Python block: what that block prints. The test compares it word by word; numbers agree within
  the stated relative tolerance (default 0.1 %), ``...`` stands for any words.
"""

from __future__ import annotations

import math
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from pymoo_rail.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = [README, *sorted(DOCS.glob("*.md"))]
MARKS = ("slow", "skip")
_BLOCK = re.compile(r"(?:<!-- (?P<kind>snippet|output)(?::\s*(?P<rest>[^\n]*?))?\s*-->\n)?"
                    r"^```(?P<lang>\w+)\n(?P<code>.*?)^```", re.S | re.M)
_TOLERANCE = re.compile(r"within\s+([0-9.]+)\s*%")
_SEPARATOR = "----- end of docs block {} -----"


def snippets(page: Path, language: str = "python") -> list[tuple[str | None, int, str]]:
    """(mark, line of the first code line, code) of every ``language`` block of a page."""
    return [(mark, line, code) for mark, lang, line, code, _ in _parse(page) if lang == language]


def _parse(page: Path) -> list[tuple[str | None, str, int, str, str | None]]:
    """(mark, language, first code line, code, reason or output tolerance) of every block of a page."""
    text = page.read_text()
    rows = []
    for m in _BLOCK.finditer(text):
        rest = m.group("rest") or ""
        if m.group("kind") == "output":
            mark, reason = "output", rest
        elif m.group("kind") == "snippet":
            mark, _, reason = (part.strip() for part in rest.partition(":"))
        else:
            mark, reason = None, None
        rows.append((mark, m.group("lang"), text.count("\n", 0, m.start("code")) + 1, m.group("code"), reason))
    return rows


def expected_outputs(page: Path) -> dict[int, tuple[str, float]]:
    """Index of a Python block -> (the text it prints, relative tolerance), from ``output`` blocks."""
    expected, index = {}, -1
    for mark, lang, _, code, reason in _parse(page):
        if lang == "python":
            index += 1
        elif mark == "output" and index >= 0:
            tolerance = _TOLERANCE.search(reason or "")
            expected[index] = (code, float(tolerance.group(1)) / 100 if tolerance else 1e-3)
    return expected


def _words(text: str) -> list[str]:
    return re.findall(r"\.\.\.|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[^\s\d.+-]+|[.+-]", text)


def _number(word: str) -> float | None:
    try:
        return float(word)
    except ValueError:
        return None


def _same(expected: str, actual: str, rel: float) -> bool:
    a, b = _number(expected), _number(actual)
    if a is None or b is None:
        return expected == actual
    return math.isclose(a, b, rel_tol=rel, abs_tol=1e-12)


def output_matches(expected: str, actual: str, rel: float) -> bool:
    """Word by word, numbers within ``rel``; ``...`` in ``expected`` matches any run of words."""
    want, got = _words(expected), _words(actual)

    def match(i: int, j: int) -> bool:
        if i == len(want):
            return j == len(got)
        if want[i] == "...":
            return any(match(i + 1, k) for k in range(j, len(got) + 1))
        return j < len(got) and _same(want[i], got[j], rel) and match(i + 1, j + 1)

    return match(0, 0)


def page_script(page: Path, with_slow: bool) -> tuple[str, list[int]]:
    """The page's Python blocks as one script (line numbers kept for tracebacks), and the indices run."""
    lines: list[str] = []
    ran = []
    for index, (mark, line, code) in enumerate(snippets(page)):
        if mark == "skip" or (mark == "slow" and not with_slow):
            continue
        lines += [""] * (line - 1 - len(lines))  # so that a traceback names the line of the page
        lines += code.splitlines()
        # only the main process: a study's pool workers import the script and must not print separators
        lines.append(f"if __name__ == '__main__': print({_SEPARATOR.format(index)!r}, flush=True)")
        ran.append(index)
    return "\n".join(lines) + "\n", ran


def run_page(page: Path, with_slow: bool, folder: Path) -> int:
    """Run a page's Python blocks in order as one script; check their stated output; returns how many ran."""
    script, ran = page_script(page, with_slow)
    path = folder / page.name.replace(".md", "_md.py")
    path.write_text(script)
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, path.name], cwd=folder, env=env, capture_output=True, text=True)
    assert done.returncode == 0, f"{page.name} as a script failed:\n{done.stderr[-3000:]}"
    printed = done.stdout
    for index in ran:
        before, _, printed = printed.partition(_SEPARATOR.format(index) + "\n")
        if index in expected_outputs(page):
            text, rel = expected_outputs(page)[index]
            assert output_matches(text, before, rel), (
                f"{page.name}, Python block {index + 1}: printed\n{before}\nthe page says (within {rel:.1%})\n{text}")
    return len(ran)


def blocks(language: str) -> list[str]:
    return [code for _, _, code in snippets(README, language)]


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_readme_python_snippet_runs_on_its_own(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # snippets write files (run.csv)
    exec(compile(blocks("python")[index], f"README.md python block {index}", "exec"), {"__name__": "__readme__"})


DOC_PAGES = [p for p in PAGES[1:] if snippets(p)]


@pytest.mark.parametrize("page", [p for p in DOC_PAGES if any(m is None for m, _, _ in snippets(p))],
                         ids=lambda p: p.name)
def test_docs_python_snippets_run(page, tmp_path):
    assert run_page(page, with_slow=False, folder=tmp_path) > 0


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in DOC_PAGES if any(m == "slow" for m, _, _ in snippets(p))],
                         ids=lambda p: p.name)
def test_docs_slow_python_snippets_run(page, tmp_path):
    n_skipped = sum(mark == "skip" for mark, _, _ in snippets(page))
    assert run_page(page, with_slow=True, folder=tmp_path) == len(snippets(page)) - n_skipped


def test_every_docs_snippet_compiles():
    # the slow ones too: a syntax error shows without running them
    for page in PAGES:
        for _, line, code in snippets(page):
            compile("\n" * (line - 1) + code, str(page.relative_to(ROOT)), "exec")


def test_snippet_marks_are_known_and_give_a_reason():
    marks = [(page.name, line, mark, reason) for page in PAGES for mark, lang, line, _, reason in _parse(page)
             if mark is not None and mark != "output"]
    assert [m for m in marks if m[2] not in MARKS] == []
    assert [m for m in marks if not (m[3] or "").strip()] == []  # every slow or skipped snippet says why
    # an output block follows a Python block
    for page in PAGES:
        rows = _parse(page)
        for before, row in zip(rows, rows[1:]):
            if row[0] == "output":
                assert before[1] == "python" and row[1] == "text", (page.name, row[2])


def test_output_comparison():
    assert output_matches("energy 12.25 kWh at 150 s", "energy 12.2512 kWh at 150.0 s", 1e-3)
    assert not output_matches("energy 12.25 kWh", "energy 12.40 kWh", 1e-3)
    assert not output_matches("energy 12.25 kWh", "energy 12.25 MWh", 1e-3)
    assert output_matches("took ... s, 0.242 kWh", "took 18.8 CPU s, 0.2424 kWh", 0.01)
    assert not output_matches("0.26", "0.242", 0.01)
    assert output_matches("[1.5e-3, -2]", "[0.0015, -2.0]", 1e-9)


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
