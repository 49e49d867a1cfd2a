"""``python -m bridges.jsbsim OPTIONS_JSON``: run the simulator bridge as its own process.

It prints one JSON line on stdout, device name → pty path, as soon as the ptys exist;
with ``hold`` set it then waits for the line ``run`` on stdin before the first frame (the
vehicle's drivers open their ports in between), and at the end of ``duration_s`` prints
``done`` and keeps the ptys open until stdin says ``quit`` or closes. SIGINT/SIGTERM end
it cleanly.
"""

from __future__ import annotations

import json
import logging
import os
import select
import signal
import sys

from bridges.jsbsim.bridge import SimBridge
from bridges.jsbsim.options import BridgeOptions

log = logging.getLogger("bridges.jsbsim")


def _wait_for_run() -> None:
    for line in sys.stdin:
        if line.strip() == "run":
            return
    raise SystemExit(0)  # stdin closed: whoever started us is gone


def _wait_for_quit(bridge: SimBridge) -> None:
    while not bridge.stopping:
        ready, _, _ = select.select([sys.stdin], [], [], 0.2)
        if ready and sys.stdin.readline() in ("", "quit\n"):
            return


def main(argv: list[str] | None = None) -> int:
    """Entry point; argv[0] is ``BridgeOptions`` as JSON."""
    args = sys.argv[1:] if argv is None else argv
    logging.basicConfig(level="INFO", format="%(asctime)s sim_bridge %(levelname)s %(message)s")
    opts = BridgeOptions.from_json(args[0])
    # JSBSim prints its banner on stdout, which is our protocol channel: keep a private
    # copy of stdout for the protocol and silence the rest.
    protocol = os.fdopen(os.dup(sys.stdout.fileno()), "w")
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    try:
        bridge = SimBridge(opts)
    except ValueError as exc:  # a line that cannot be opened (hardware in the loop)
        sys.stderr.write(f"error: {exc}\n")
        return 2
    signal.signal(signal.SIGTERM, lambda *_: bridge.stop())
    signal.signal(signal.SIGINT, lambda *_: bridge.stop())
    try:
        protocol.write(json.dumps(bridge.device_paths()) + "\n")
        protocol.flush()
        bridge.run(_wait_for_run if opts.hold else None)
        if opts.hold and not bridge.stopping:
            # Keep the lines up until the vehicle has stopped reading them.
            protocol.write("done\n")
            protocol.flush()
            _wait_for_quit(bridge)
    finally:
        bridge.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
