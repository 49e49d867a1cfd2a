"""``companion sim`` for one vehicle, once the command line has handed its process over.

``python -m ground.sitl.session_process`` is started only by ``companion sim``
(``handover.exec_module``) with the options it parsed and checked. It runs the simulator
bridge and the vehicle (``run_sim``) in a process without the command line's libraries, as
``companion run`` does on board, then lists the run's flight logs.
"""

from __future__ import annotations

import sys
from pathlib import Path

from bridges.jsbsim.options import BridgeOptions
from companion.exec_control.config import ConfigError
from companion.exec_control.handover import received
from companion.exec_control.vehicle_process import config_refused, setup_logging
from ground.sitl import session
from ground.sitl.requests import SimRequest
from ground.sitl.run_logs import keep_beside, log_names, new_logs


def run_one(
    req: SimRequest, opts: BridgeOptions, log_level: str, logs_dir: Path, truth: Path | None
) -> int:
    """One vehicle; then where its flight logs are (copied beside the truth CSV)."""
    before = log_names(logs_dir)
    try:
        code = session.run_sim(req, opts, log_level)
    except ConfigError as exc:
        return config_refused(exc)
    logs = new_logs(logs_dir, before)
    for path in logs:
        sys.stderr.write(f"flight log: {path}\n")
    for path in keep_beside(truth, logs) if truth is not None else []:
        sys.stderr.write(f"flight log copied to {path}\n")
    return code


def main(argv: list[str] | None = None) -> int:
    """Fly the handed-over request: (SimRequest, BridgeOptions, log level, logs dir, truth)."""
    req, opts, log_level, logs_dir, truth = received(sys.argv[1:] if argv is None else argv)
    setup_logging(log_level)
    return run_one(req, opts, log_level, logs_dir, truth)


if __name__ == "__main__":
    sys.exit(main())
