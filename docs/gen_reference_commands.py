"""The MAVLink command and command-line reference pages (``docs/gen_reference.py`` writes
them with the others)."""

from __future__ import annotations

import ast
import re
from typing import Any

from gen_reference import GENERATED, REPO, number, table

# --- MAVLink commands -------------------------------------------------------------------------

SENTENCE = re.compile(r"(?<=[a-z0-9)])\. (?=[A-Z])")
REGISTER = re.compile(r"service\.register\((?:d\.)?(\w+), self\.(\w+)\)")


def handlers() -> list[tuple[str, str, str]]:
    """(command name, handler, its docstring's first line) as the link registers them."""
    found = []
    for path in sorted((REPO / "companion" / "link" / "commands").glob("*.py")):
        text = path.read_text()
        docs = {
            node.name: (ast.get_docstring(node) or "").split("\n\n")[0]
            for node in ast.walk(ast.parse(text))
            if isinstance(node, ast.FunctionDef)
        }
        module = ".".join(path.relative_to(REPO).with_suffix("").parts)
        for command, method in REGISTER.findall(text):
            found.append((command, f"`{module}` `{method}`", " ".join(docs[method].split())))
    return found


def rule_text(command: int) -> str:
    from companion.link import command_rules as rules

    parts = []
    for p in rules.RULES.get(command, ()):
        text = f"param{p.index} {p.name} in [{number(p.lo)}, {number(p.hi)}]"
        text += ", whole" if p.whole else ""
        text += ", NaN = not given" if p.optional else ""
        parts.append(text)
    if command in rules.POSITION_COMMANDS:
        parts.append("COMMAND_INT: global frames only")
    if command in rules.EXTRA_CHECKS:
        check = rules.EXTRA_CHECKS[command]
        parts.append(" ".join((check.__doc__ or check.__name__.strip("_")).split("_")))
    return "; ".join(parts) or "no parameters read"


def spec_text(command: int) -> str:
    """MAVLink's own description of the command, its first sentence."""
    from companion.link.codec import dialect

    entry = dialect.enums["MAV_CMD"].get(command)
    text = " ".join((entry.description if entry else "").split())
    return SENTENCE.split(text)[0].rstrip(".") + "." if text else ""


def commands_page() -> str:
    from companion.link.codec import dialect
    from companion.link.command_service import SET_MODE_MESSAGE

    rows = []
    for name, handler, doc in sorted(handlers()):
        number_ = SET_MODE_MESSAGE if name == "SET_MODE_MESSAGE" else getattr(dialect, name)
        shown = "SET_MODE (message)" if name == "SET_MODE_MESSAGE" else name
        rows.append((shown, number_, rule_text(number_), handler, doc or spec_text(number_)))
    return (
        "# MAVLink commands\n\n" + GENERATED
        + "Every command the link accepts (COMMAND_LONG and COMMAND_INT; the SET_MODE message "
        "goes through the same rules) with the rule its parameters must keep "
        "(`companion/link/command_rules.py`). A broken rule is answered MAV_RESULT_DENIED "
        "with a status text naming the field and counted in the `refused` column of "
        "`companion status`; any other command is answered UNSUPPORTED at once. Each gets "
        "exactly one COMMAND_ACK.\n\n"
        + table(("Command", "Id", "Rule", "Handler", "What it does"), rows)
    )  # fmt: skip


# --- the command line -----------------------------------------------------------------------


def cli_page() -> str:
    import typer.main

    from companion.cli import app

    root = typer.main.get_command(app)
    parts = ["# Command line\n\n" + GENERATED, "Every `companion` command and its options "
             "(`companion COMMAND --help` prints the same).\n"]  # fmt: skip
    parts += cli_sections(root, "companion")
    return "".join(parts)


def cli_sections(group: Any, prefix: str) -> list[str]:
    out = []
    for name in sorted(group.commands):
        command = group.commands[name]
        if command.hidden:
            continue
        path = f"{prefix} {name}"
        help_ = " ".join((command.help or "").split("\n\n")[0].split())
        out.append(f"\n## `{path}`\n\n{help_}\n\n")
        if hasattr(command, "commands"):  # a group: its subcommands follow
            out += cli_sections(command, path)
            continue
        rows = [option_row(p) for p in command.params if not getattr(p, "hidden", False)]
        out.append(table(("Argument or option", "Default", "Meaning"), rows))
    return out


def option_row(param: Any) -> tuple[str, str, str]:
    names = " / ".join(f"`{o}`" for o in (*param.opts, *param.secondary_opts))
    if param.param_type_name == "argument":
        names = f"`{param.name.upper()}` (argument)"
    default = "required" if param.required else param.default
    if callable(default) or default is None or default == () or default == []:
        default = ""
    # A default under this checkout (the shipped config) is shown as the repository path.
    shown = str(default).replace(f"{REPO}/", "")
    # A help text escapes a bracket for the terminal's markup ("\\[vehicle]"); not here.
    return names, shown, (getattr(param, "help", "") or "").replace("\\[", "[")
