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
    "atomic": 0, "lockfiles": 0, "rowcache": 0, "constants": 0, "algorithms": 0, "indicators": 0,
    "model": 1,
    "cases": 2,
    "sim": 3,
    "optimal": 4,
    "control": 5,
    "problems": 6,
    "journeys": 7,
    "suite": 8,
    "experiments": 9, "plotting": 9,
    "cli": 10, "warmup": 10,
}
KNOW_NO_PYMOO = ("model", "cases", "sim", "optimal", "control")  # usable without the optimisers
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


def _package_imports():
    """(where, room of the importer, module path parts, imported names) of every package import."""
    for path in _sources():
        for line, module, names in _imports(path):
            yield f"{path.relative_to(PACKAGE.parent)}:{line}", _room(path), module.split("."), names


def test_arrows_point_down():
    wrong = []
    for where, src, parts, _ in _package_imports():
        if len(parts) < 2 or parts[1] == src:
            continue  # the package root (version), or the room itself
        dst = parts[1]
        if src in PYMOO_ONLY or LAYERS.get(dst, 99) > LAYERS[src]:
            wrong.append(f"{where} {src} -> {dst}")
    assert not wrong, "imports against the layers:\n" + "\n".join(wrong)


def _third_party_imports(path: Path):
    """(line, top-level module) of every import of another distribution in a file, at any depth."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.lineno, node.module.split(".")[0]
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name.split(".")[0]


def test_the_lower_rooms_know_no_pymoo():
    # the simulator, the exact solver and the controllers work without the optimisation layer
    wrong = [f"{path.relative_to(PACKAGE.parent)}:{line}" for path in _sources() if _room(path) in KNOW_NO_PYMOO
             for line, top in _third_party_imports(path) if top == "pymoo"]
    assert not wrong, "pymoo imported below the problems:\n" + "\n".join(wrong)


def test_imports_inside_functions_count(tmp_path):
    # a lazy import is an arrow too: the checker sees it at any depth
    lazy = tmp_path / "lazy.py"
    lazy.write_text("class A:\n    def f(self):\n        if True:\n            import pymoo_rail.cli\n"
                    "            import pymoo.core.problem\n")
    assert [m for _, m, _ in _imports(lazy)] == ["pymoo_rail.cli"]
    assert ("pymoo" in [m for _, m in _third_party_imports(lazy)])


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def test_no_private_name_crosses_a_module():
    # a private module (``algorithms/_bees.py``) serves the modules of its own room only;
    # a private name (``_full_step``) serves its own module only
    wrong = []
    for where, room, parts, names in _package_imports():
        private = [n for n in names if _private(n)]
        if len(parts) > 1 and parts[1] != room:
            private += [p for p in parts if _private(p)]
        if private:
            wrong.append(f"{where} {'.'.join(parts)}: {', '.join(private)}")
    assert not wrong, "private names imported across modules:\n" + "\n".join(wrong)


@pytest.mark.parametrize("rule", ["arrows", "private"])
def test_the_checks_catch_a_violation(tmp_path, rule):
    # the checker itself must see an upward and a private import
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from pymoo_rail.cli import main\n    from pymoo_rail.sim.kernel import _x\n")
    found = list(_imports(bad))
    assert ("pymoo_rail.cli", ["main"]) == found[0][1:]
    assert ("pymoo_rail.sim.kernel", ["_x"]) == found[1][1:]


def _unit_factor_uses(path: Path) -> list[str]:
    """Places that define or spell out a unit factor instead of importing it from ``pymoo_rail.constants``."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                if isinstance(t, ast.Name) and any(k in t.id for k in ("KMH_PER_MS", "J_PER_KWH", "MS_TO_KMH")):
                    found.append(f"{path.name}:{node.lineno} defines {t.id}")
        elif isinstance(node, ast.Constant) and type(node.value) is float and node.value == 3.6e6:
            found.append(f"{path.name}:{node.lineno} spells out 3.6e6 (J_PER_KWH)")
        elif isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Mult, ast.Div)):
            for side in (node.left, node.right):
                if isinstance(side, ast.Constant) and side.value == 3.6:
                    other = ast.unparse(node.right if side is node.left else node.left)
                    if isinstance(node.op, ast.Div) and side is node.right or "_ms" in other or "speed" in other:
                        found.append(f"{path.name}:{node.lineno} spells out 3.6 (KMH_PER_MS) in {ast.unparse(node)}")
    return found


def test_unit_factors_are_defined_once():
    wrong = [w for p in _sources() if p != PACKAGE / "constants.py" for w in _unit_factor_uses(p)]
    assert not wrong, "use pymoo_rail.constants:\n" + "\n".join(wrong)


def test_the_unit_factor_check_catches_a_copy(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("J_PER_KWH = 3.6e6\nv_kmh = speed_ms * 3.6\nv_ms = 80 / 3.6\nfigsize = (4.6, 3.6 * 2)\n")
    found = _unit_factor_uses(bad)
    assert len(found) == 4 and "figsize" not in " ".join(found)  # define + 3.6e6 + two spelled-out 3.6


def test_benchmark_scripts_use_only_public_names():
    # a benchmark is a user's script: what it needs from the package is public API
    wrong = []
    for path in sorted((PACKAGE.parent / "benchmarks").glob("*.py")):
        for line, module, names in _imports(path):
            private = [n for n in names if _private(n)] + [p for p in module.split(".") if _private(p)]
            if private:
                wrong.append(f"benchmarks/{path.name}:{line} {module}: {', '.join(private)}")
    assert not wrong, "private names used by benchmark scripts:\n" + "\n".join(wrong)


def _undocumented(path: Path) -> list[str]:
    """Public functions, classes and methods of a module without a docstring."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    missing = []

    def visit(body, prefix: str) -> None:
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and not node.name.startswith("_"):
                if ast.get_docstring(node) is None:
                    missing.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {prefix}{node.name}")
                if isinstance(node, ast.ClassDef):
                    visit(node.body, f"{prefix}{node.name}.")

    visit(tree.body, "")
    return missing


def test_every_public_name_has_a_docstring():
    # private modules (``_bees.py``) and private names are exempt
    missing = [m for p in _sources() if not p.name.startswith("_") for m in _undocumented(p)]
    assert not missing, "public names without a docstring:\n" + "\n".join(missing)
