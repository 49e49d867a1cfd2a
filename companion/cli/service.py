"""``companion service install`` / ``uninstall``: the vehicle as a systemd service."""

from __future__ import annotations

import getpass
import os
import pwd
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Annotated

import typer

from companion.cli.app import CONFIG_OPT, NS_OPT, app, err, load_checked, out
from companion.params.atomic import atomic_write_text

service_app = typer.Typer(help="Start the vehicle at boot: a systemd service.")
app.add_typer(service_app, name="service")

NAME_OPT = typer.Option("--name", help="the unit's name (NAME.service)")
ROOT_OPT = typer.Option(
    "--root", help="write under this directory instead of / (systemctl is then left alone)"
)
UNIT_DIR_OPT = typer.Option(
    "--unit-dir", help="directory of unit files (systemctl is then left alone)"
)


def _command() -> tuple[str, ...]:
    """The companion command by absolute path, as systemd needs it."""
    script = Path(sys.executable).with_name("companion")
    if script.is_file() and os.access(script, os.X_OK):
        return (str(script),)
    return (sys.executable, "-m", "companion")


def _default_user() -> str:
    """Who ran ``sudo companion service install`` (never root unless asked by name)."""
    return os.environ.get("SUDO_USER") or getpass.getuser()


def _user_exists(name: str) -> bool:
    try:
        pwd.getpwnam(name)
    except KeyError:
        return False
    return True


def _systemctl(*args: str) -> None:
    if shutil.which("systemctl") is None:
        err.print(f"systemctl not found: run `systemctl {' '.join(args)}` where systemd runs")
        return
    done = subprocess.run(["systemctl", *args], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        err.print(f"systemctl {' '.join(args)}: {done.stderr.strip()}", highlight=False)


@service_app.command("install")
def install(
    config: Annotated[Path, CONFIG_OPT],
    user: Annotated[str | None, typer.Option(help="account the vehicle runs as")] = None,
    namespace: Annotated[str | None, NS_OPT] = None,
    name: Annotated[str, NAME_OPT] = "companion",
    root: Annotated[Path | None, ROOT_OPT] = None,
    unit_dir: Annotated[Path | None, UNIT_DIR_OPT] = None,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "INFO",
) -> None:
    """Write the unit that runs `companion run --config FILE` at boot, and enable it."""
    from companion.exec_control.service_unit import UNIT_DIR, UnitSpec, unit_path, unit_text

    load_checked(config, namespace)  # a config refused now would be refused at every boot
    who = user or _default_user()
    manage = root is None and unit_dir is None  # this machine's systemd, not a staging place
    if manage and not _user_exists(who):
        err.print(f"[red]no user {who!r} on this machine[/red] (give --user NAME)")
        raise typer.Exit(2)
    if who == "root" and user is None:
        err.print("[yellow]the vehicle will run as root: give --user NAME to avoid it[/yellow]")
    spec = UnitSpec(config.resolve(), who, _command(), name, namespace, log_level)
    path = unit_path(unit_dir or UNIT_DIR, name, root)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, unit_text(spec), shared=True)
    out.print(f"wrote {path} (runs as {who}, state in /var/lib/companion)", highlight=False)
    if manage:
        _systemctl("daemon-reload")
        _systemctl("enable", f"{name}.service")
        out.print(f"enabled: starts at boot. Now: sudo systemctl start {name}", highlight=False)
        out.print(f"its log: journalctl -u {name} -f", highlight=False)


@service_app.command("uninstall")
def uninstall(
    name: Annotated[str, NAME_OPT] = "companion",
    root: Annotated[Path | None, ROOT_OPT] = None,
    unit_dir: Annotated[Path | None, UNIT_DIR_OPT] = None,
) -> None:
    """Stop and disable the service and remove its unit (its state directory stays)."""
    from companion.exec_control.service_unit import UNIT_DIR, unit_path

    path = unit_path(unit_dir or UNIT_DIR, name, root)
    manage = root is None and unit_dir is None
    if manage:
        _systemctl("disable", "--now", f"{name}.service")
    if not path.exists():
        err.print(f"no unit at {path}")
        raise typer.Exit(1)
    path.unlink()
    if manage:
        _systemctl("daemon-reload")
    out.print(f"removed {path}; parameters, missions and logs stay in /var/lib/companion")
