"""The documentation site builds with warnings as errors, every page is in its navigation,
and every `companion ...` command its code blocks (and the README's) show names a command
and options that exist."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import typer.main
from mkdocs.config import load_config
from typer.testing import CliRunner

from companion.cli import app
from tests.support.vehicle import REPO

DOCS = REPO / "docs"
FENCE = re.compile(r"^ *```(\w*)\n(.*?)^ *```", re.M | re.S)
COMMAND = re.compile(r"(?:^|uv run |\$ )companion (.*)")


def test_site_builds_strict(tmp_path):
    """Strict: a broken link between pages, a missing anchor or a page left out of the
    navigation is a warning, and a warning fails the build."""
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(tmp_path / "site")],
        cwd=REPO, capture_output=True, text=True, timeout=170, env=env,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert "WARNING" not in done.stderr, done.stderr
    assert (tmp_path / "site" / "reference" / "parameters" / "index.html").exists()


def _nav_files(items: list) -> set[str]:
    found: set[str] = set()
    for item in items:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        if isinstance(value, list):
            found |= _nav_files(value)
        elif isinstance(value, str) and value.endswith(".md"):
            found.add(value)
    return found


def test_every_page_is_in_the_navigation():
    config = load_config(str(REPO / "mkdocs.yml"))
    in_nav = _nav_files(config["nav"])
    pages = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md")}
    assert pages - in_nav == set(), "pages left out of mkdocs.yml's nav"
    assert in_nav - pages == set(), "nav entries with no page"


def shown_commands() -> list[tuple[str, str]]:
    """(where, the words after `companion`) of every command line in a shell code block."""
    found = []
    for path in [REPO / "README.md", *sorted(DOCS.rglob("*.md"))]:
        for lang, body in FENCE.findall(path.read_text()):
            if lang not in ("", "sh", "bash", "console", "shell"):
                continue
            for line in body.replace("\\\n", " ").splitlines():
                match = COMMAND.search(line.split(" #")[0].strip())
                if match:
                    found.append((path.relative_to(REPO).as_posix(), match.group(1).strip()))
    return found


def _resolve(words: list[str]):
    """The click command the words name, and the words left for its options."""
    command = typer.main.get_command(app)
    while words and hasattr(command, "commands") and words[0] in command.commands:
        command, words = command.commands[words[0]], words[1:]
    return command, words


@pytest.mark.parametrize(("where", "line"), shown_commands())
def test_shown_command_exists_and_its_options_too(where, line):
    words = shlex.split(line)
    command, rest = _resolve(words)
    assert not hasattr(command, "commands"), f"{where}: `companion {line}` names no command"
    names = {o for p in command.params for o in (*p.opts, *p.secondary_opts)}
    unknown = [w.split("=")[0] for w in rest if w.startswith("-") and w.split("=")[0] not in names]
    assert unknown == [], f"{where}: `companion {line}`: no such option"
    path = words[: len(words) - len(rest)]
    result = CliRunner().invoke(app, [*path, "--help"])
    assert result.exit_code == 0, f"{where}: companion {' '.join(path)} --help: {result.output}"


def test_the_readme_names_the_command_that_serves_the_site():
    assert "python3 -m uv run mkdocs serve" in (REPO / "README.md").read_text()
    assert Path(REPO / "mkdocs.yml").exists()


def test_the_readmes_links_reach_files():
    """The README is read on GitHub, outside the site: its relative links name files."""
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", (REPO / "README.md").read_text())
    local = [link for link in links if "://" not in link]
    assert local, "the README links to the documentation"
    assert [link for link in local if not (REPO / link).is_file()] == []
