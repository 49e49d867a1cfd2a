"""``companion run`` once the command line has handed its process over: the supervisor.

``python -m companion.exec_control.vehicle_process`` is started only by the ``companion``
command (``handover.exec_module``), which parses the options and nothing more: the config
is loaded and checked here, so the vehicle's libraries are imported once. A plain
``companion run`` calls ``run_vehicle`` in its own process without loading the command
line at all (``companion.launch``). This process
never imports the command line's libraries (typer, rich, pydantic), and neither do the
fork server and the plug-ins it forks.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

from companion.exec_control.handover import received

EXIT_CONFIG = 2  # the status of every ``companion`` command that refuses a config


def setup_logging(level: str, who: str = "exec_control") -> None:
    """The log format of every ``companion`` command and of the vehicle it runs."""
    logging.basicConfig(level=level, format=f"%(asctime)s {who} %(levelname)s %(message)s")


def config_refused(exc: Exception) -> int:
    """Say why the config was refused, on stderr; the exit status that goes with it."""
    sys.stderr.write(f"config error: {exc}\n")
    return EXIT_CONFIG


def main(argv: list[str] | None = None) -> int:
    """Check the handed-over config (path, namespace, log level), then run it until a stop
    signal. A refused config: its error on stderr and ``EXIT_CONFIG``, nothing started."""
    config, namespace, log_level = received(sys.argv[1:] if argv is None else argv)
    return run_vehicle(config, namespace, log_level)


def run_vehicle(config: str, namespace: str | None, log_level: str) -> int:
    """Load and check the config, then run it until a stop signal; the exit status."""
    from companion.exec_control.config import ConfigError, load_config
    from companion.exec_control.supervisor import Supervisor
    from companion.exec_control.topology import check_topology

    setup_logging(log_level)
    log = logging.getLogger(__name__)
    # Each step of a start is a line with its time: a restart in the air is timed by them.
    log.info("starting %s", config)
    try:
        cfg = load_config(config, namespace)
        check_topology(cfg)
    except ConfigError as exc:
        return config_refused(exc)
    log.info("config read")
    _make_state_dir(cfg.vehicle.get("state_dir"), log)
    return Supervisor(cfg, log_level).run()


def _make_state_dir(state_dir: str | None, log: logging.Logger) -> None:
    """The state directory, made once here rather than by each plug-in that writes to it
    (a fresh machine, or --state-dir naming a new one); one that cannot be made is said
    here, and the vehicle flies on without what it would have kept there."""
    if not state_dir:
        return
    try:
        Path(state_dir).expanduser().mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        log.error("state directory %s cannot be made (%s): nothing will be kept", state_dir, exc)


if __name__ == "__main__":
    sys.exit(main())
