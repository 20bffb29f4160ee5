"""The import rules of docs/architecture.md, checked on the source tree.

Each room (sub-package) may import only from rooms of a lower layer or of its own layer; the
algorithms and the indicators know pymoo (and numpy/scipy) only; no private name (``_x``) is
imported from another module. Imports inside functions count too: a lazy import is still an arrow.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "pymoo_rail"

# layer of every room; a room may import rooms of its own or a lower layer
LAYERS = {
    "atomic": 0, "constants": 0, "algorithms": 0, "indicators": 0,
    "model": 1,
    "cases": 2,
    "sim": 3,
    "problems": 4, "optimal": 4, "control": 4, "journeys": 4,
    "suite": 5,
    "experiments": 6, "plotting": 6,
    "cli": 7, "warmup": 7,
}
PYMOO_ONLY = ("algorithms", "indicators")  # know no other room


def _room(path: Path) -> str:
    parts = path.relative_to(PACKAGE).parts
    return parts[0] if len(parts) > 1 else parts[0].removesuffix(".py")


def _imports(path: Path):
    """(line, module, names) of every pymoo_rail import in a file, at any depth."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0 \
                and node.module.split(".")[0] == "pymoo_rail":
            yield node.lineno, node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "pymoo_rail":
                    yield node.lineno, alias.name, []


def _sources():
    return sorted(p for p in PACKAGE.rglob("*.py") if p.name != "__init__.py" or p.parent != PACKAGE)


def test_every_room_has_a_layer():
    rooms = {_room(p) for p in _sources()}
    assert rooms <= set(LAYERS), f"rooms without a layer in docs/architecture.md: {sorted(rooms - set(LAYERS))}"


def test_arrows_point_down():
    wrong = []
    for path in _sources():
        src = _room(path)
        for line, module, _ in _imports(path):
            parts = module.split(".")
            if len(parts) < 2:
                continue  # the package root (version)
            dst = parts[1]
            if dst == src:
                continue
            if src in PYMOO_ONLY or LAYERS.get(dst, 99) > LAYERS[src]:
                wrong.append(f"{path.relative_to(PACKAGE.parent)}:{line} {src} -> {dst}")
    assert not wrong, "imports against the layers:\n" + "\n".join(wrong)


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def test_no_private_name_crosses_a_module():
    # a private module (``algorithms/_bees.py``) serves the modules of its own room only;
    # a private name (``_full_step``) serves its own module only
    wrong = []
    for path in _sources():
        room = _room(path)
        for line, module, names in _imports(path):
            parts = module.split(".")
            private = [n for n in names if _private(n)]
            if len(parts) > 1 and parts[1] != room:
                private += [p for p in parts if _private(p)]
            if private:
                wrong.append(f"{path.relative_to(PACKAGE.parent)}:{line} {module}: {', '.join(private)}")
    assert not wrong, "private names imported across modules:\n" + "\n".join(wrong)


@pytest.mark.parametrize("rule", ["arrows", "private"])
def test_the_checks_catch_a_violation(tmp_path, rule):
    # the checker itself must see an upward and a private import
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from pymoo_rail.cli import main\n    from pymoo_rail.sim.kernel import _x\n")
    found = list(_imports(bad))
    assert ("pymoo_rail.cli", ["main"]) == found[0][1:]
    assert ("pymoo_rail.sim.kernel", ["_x"]) == found[1][1:]
