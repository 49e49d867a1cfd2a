"""What keeps the code's shape honest: ruff, the import-linter contracts, and sizes."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

from tests.support.vehicle import REPO


def run(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(argv, cwd=REPO, capture_output=True, text=True, timeout=120)


def test_ruff_finds_nothing():
    rooms = ("companion", "bridges", "ground", "tests", "benchmarks")
    done = run(sys.executable, "-m", "ruff", "check", *rooms)
    assert done.returncode == 0, done.stdout + done.stderr


def test_import_contracts_hold():
    exe = shutil.which("lint-imports")
    assert exe, "import-linter is a dev dependency"
    done = run(exe)
    assert done.returncode == 0, done.stdout + done.stderr


def _program_files() -> list[Path]:
    rooms = ("companion", "bridges", "ground")
    return sorted(p for room in rooms for p in (REPO / room).rglob("*.py"))


def _body_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Lines of a function's body, its signature and docstring left out (a typer command's
    options are its signature)."""
    body = node.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]
    return 0 if not body else body[-1].end_lineno - body[0].lineno + 1  # type: ignore[operator]


def test_program_files_stay_under_400_lines_and_functions_under_50():
    long_files = [
        f"{p.relative_to(REPO)}: {n}"
        for p in _program_files()
        if (n := p.read_text().count("\n")) > 400
    ]
    long_functions = [
        f"{p.relative_to(REPO)}:{node.name}: {_body_lines(node)}"
        for p in _program_files()
        for node in ast.walk(ast.parse(p.read_text()))
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and _body_lines(node) > 50
    ]
    assert long_files == [] and long_functions == []


def test_no_two_onboard_modules_share_a_basename():
    """A reader who meets ``modes.py`` should not have to ask which one (issue 44.6). A
    plug-in may share its library's name (plugins/sensors/os3000.py runs
    sensors/os3000.py): the plug-in contract names a plug-in by its kind."""
    plugins = REPO / "companion" / "plugins"
    seen: dict[str, list[Path]] = {}
    for path in sorted((REPO / "companion").rglob("*.py")):
        if path.name != "__init__.py" and not path.is_relative_to(plugins):
            seen.setdefault(path.name, []).append(path.relative_to(REPO))
    shared = {name: paths for name, paths in seen.items() if len(paths) > 1}
    assert shared == {}, shared


def _module_name(path: Path) -> str:
    parts = path.relative_to(REPO).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imported(node: ast.Import | ast.ImportFrom, here: str, is_package: bool) -> list[str]:
    """The modules an import statement names (``from a import b``: ``a.b`` when that is a
    module, else ``a``), relative imports resolved against ``here``."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    base = node.module or ""
    if node.level:
        package = here.split(".")
        package = package if is_package else package[:-1]
        package = package[: len(package) - node.level + 1]
        base = ".".join([*package, base] if base else package)
    return [base, *(f"{base}.{alias.name}" for alias in node.names)]


def _import_graph(room: str) -> dict[str, set[str]]:
    """Every module under ``room`` and the modules of ``room`` it imports, those under
    ``if TYPE_CHECKING:`` and inside functions included."""
    paths = {_module_name(p): p for p in sorted((REPO / room).rglob("*.py"))}
    graph: dict[str, set[str]] = {}
    for name, path in paths.items():
        edges = graph.setdefault(name, set())
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import | ast.ImportFrom):
                named = _imported(node, name, path.name == "__init__.py")
                if isinstance(node, ast.ImportFrom) and any(n in paths for n in named[1:]):
                    named = named[1:]  # submodules: the package itself is not the point
                edges.update(n for n in named if n in paths and n != name)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The modules that import one another round a cycle, group by group (Tarjan's strongly
    connected components of more than one module)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    groups: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in sorted(graph[node]):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            group = stack[stack.index(node) :]
            del stack[stack.index(node) :]
            if len(group) > 1:
                groups.append(sorted(group))

    for start in sorted(graph):
        if start not in index:
            visit(start)
    return sorted(groups)


def test_companion_has_no_import_cycle():
    """No module of companion/ imports, even for type checking only, a module that imports
    it back (issue 44.4: collaborators with explicit inputs, not mix-ins on ``self``)."""
    graph = _import_graph("companion")
    shown = [
        ", ".join(f"{m} -> {n}" for m in c for n in sorted(graph[m] & set(c)))
        for c in _cycles(graph)
    ]
    assert shown == [], "\n".join(shown)
