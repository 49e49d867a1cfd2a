"""``companion run`` once the command line has handed its process over: the supervisor.

``python -m companion.exec_control.vehicle_process`` is started only by the ``companion``
command (``handover.exec_module``), with the checked config; this process never imports
the command line's libraries (typer, rich, pydantic), and neither do the fork server and
the plug-ins it forks.
"""

from __future__ import annotations

import logging
import sys

from companion.exec_control.handover import received

EXIT_CONFIG = 2  # the status of every ``companion`` command that refuses a config


def setup_logging(level: str, who: str = "exec_control") -> None:
    """The log format of every ``companion`` command and of the vehicle it runs."""
    logging.basicConfig(level=level, format=f"%(asctime)s {who} %(levelname)s %(message)s")


def main(argv: list[str] | None = None) -> int:
    """Run the handed-over config (a ``VehicleConfig``) until a stop signal."""
    from companion.exec_control.supervisor import Supervisor

    cfg, log_level = received(sys.argv[1:] if argv is None else argv)
    setup_logging(log_level)
    return Supervisor(cfg, log_level).run()


if __name__ == "__main__":
    sys.exit(main())
