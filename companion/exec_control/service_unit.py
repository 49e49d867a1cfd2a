"""The systemd unit that starts the vehicle at boot (``companion service install``).

What each line is for:
- ``ExecStart`` runs ``companion run --config FILE``; the command line hands its process
  over to the supervisor (same pid), so the supervisor is the service's main process.
- ``KillMode=mixed``: the stop signal (SIGTERM) goes to the supervisor alone, which stops
  the flight plug-ins first (servos to their safe positions), then the rest, each with a
  grace before SIGKILL (``supervisor.STOP_GRACE_S``); systemd's own SIGKILL reaches whatever
  is left after ``TimeoutStopSec``. The default (every process at once) would race the
  supervisor's order.
- ``Restart=on-failure``: a supervisor that dies or exits non-zero is started again; a
  clean stop (``systemctl stop``, exit status 0) is not. A refused config (exit status 2)
  would only fail again, so it is not restarted (``RestartPreventExitStatus``).
- ``RestartSec=100ms``: at once. A supervisor that dies in the air must be back flying
  within 3 s (its plug-ins die with it; the card holds the servos meanwhile), and the
  restart itself takes most of that on a slow board: the 2 s this unit used to wait were
  most of the budget. ``StartLimitIntervalSec=0``: never give up (systemd's default stops
  restarting after 5 starts in 10 s, which an aircraft in the air cannot afford).
- ``StateDirectory=companion``: systemd makes ``/var/lib/companion``, owned by the user;
  ``COMPANION_STATE_DIR`` points the config's default state directory there (parameters,
  missions, flight logs: ``/var/lib/companion/NAME/NAMESPACE``).
- ``SupplementaryGroups=dialout``: the serial devices belong to dialout.
- Output goes to the journal (``journalctl -u companion``), one line a record.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from pathlib import Path

DEFAULT_NAME = "companion"
UNIT_DIR = Path("/etc/systemd/system")
STOP_TIMEOUT_S = 10  # the supervisor needs under 2.5 s; systemd's SIGKILL only after this
EXIT_CONFIG = 2


@dataclass(frozen=True)
class UnitSpec:
    """What the unit runs, as whom."""

    config: Path  # absolute
    user: str
    command: tuple[str, ...]  # the companion command, absolute path first
    name: str = DEFAULT_NAME
    namespace: str | None = None
    log_level: str = "INFO"


def unit_text(spec: UnitSpec) -> str:
    """The unit file's text."""
    run = [*spec.command, "run", "--config", str(spec.config), "--log-level", spec.log_level]
    if spec.namespace:
        run += ["--namespace", spec.namespace]
    return f"""\
# Written by `companion service install`; `companion service uninstall` removes it.
[Unit]
Description=UAV companion computer ({spec.config.name})
After=network-online.target
Wants=network-online.target
StartLimitIntervalSec=0

[Service]
Type=exec
User={spec.user}
SupplementaryGroups=dialout
# The flight chain's plug-ins raise their priority and run SCHED_FIFO
# (companion.exec_control.priority).
AmbientCapabilities=CAP_SYS_NICE
ExecStart={shlex.join(run)}
KillMode=mixed
KillSignal=SIGTERM
TimeoutStopSec={STOP_TIMEOUT_S}
Restart=on-failure
RestartSec=100ms
RestartPreventExitStatus={EXIT_CONFIG}
StateDirectory=companion
StateDirectoryMode=0750
Environment=COMPANION_STATE_DIR=%S/companion
Environment=PYTHONUNBUFFERED=1
WorkingDirectory=%S/companion
StandardOutput=journal
StandardError=journal
SyslogIdentifier={spec.name}

[Install]
WantedBy=multi-user.target
"""


def unit_path(unit_dir: Path, name: str = DEFAULT_NAME, root: Path | None = None) -> Path:
    """Where the unit file goes: ``unit_dir`` under ``root`` (``/`` when None)."""
    if root is None:
        return unit_dir / f"{name}.service"
    return root / unit_dir.relative_to(unit_dir.anchor) / f"{name}.service"
