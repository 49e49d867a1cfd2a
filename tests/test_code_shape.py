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
