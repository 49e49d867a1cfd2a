"""How long QGroundControl's parameter-metadata download takes against a running vehicle.

Usage: uv run python benchmarks/component_metadata.py [--rounds 5]

A vehicle with the link, the commander and the fixed-wing controller (whose parameters a
ground station lists) runs on loopback UDP; a pymavlink ground station asks for
COMPONENT_METADATA and downloads the general and the parameter metadata file over MAVLink
FTP the way QGroundControl's FTPManager does (OpenFileRO, BurstReadFile, ResetSessions).
Prints the files' sizes, the FTP packets, and the time from the request to both files
parsed (median and worst of the rounds).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MAVLINK20", "1")
REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from companion.bus.namespace import cleanup_namespace  # noqa: E402
from mavlink_dialect import companion as m  # noqa: E402
from tests.protocol.ftp_client import FtpDownload  # noqa: E402
from tests.protocol.mav_client import GroundStation, free_udp_port  # noqa: E402
from tests.support.configs import client_vehicle, plugin  # noqa: E402


def start_vehicle(port: int, tmp: Path, namespace: str) -> subprocess.Popen[bytes]:
    flight = plugin("control", "control.fixed_wing", "flight")
    config = tmp / "vehicle.toml"
    config.write_text(
        client_vehicle(f"udpin://127.0.0.1:{port}", tmp, flight=flight, airframe="c172p")
    )
    env = {**os.environ, "COMPANION_BUS": namespace, "PYTHONPATH": str(REPO)}
    cmd = [sys.executable, "-m", "companion", "run", "-c", str(config), "--log-level", "WARNING"]
    return subprocess.Popen(cmd, env=env, cwd=REPO)


def fetch(gcs: GroundStation) -> tuple[float, int, int, int]:
    """Seconds, general file bytes, parameter file bytes, parameters described."""
    t0 = time.monotonic()
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, 397)
    uri = gcs.recv("COMPONENT_METADATA").uri
    ftp = FtpDownload(gcs)
    general = ftp.get(uri.removeprefix("mftp://"))
    entry = json.loads(general)["metadataTypes"][0]
    params = ftp.get(entry["uri"].removeprefix("mftp://"))
    count = len(json.loads(params)["parameters"])
    return time.monotonic() - t0, len(general), len(params), count


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    namespace = f"metabench{os.getpid()}"
    with tempfile.TemporaryDirectory() as tmp:
        port = free_udp_port()
        proc = start_vehicle(port, Path(tmp), namespace)
        gcs = GroundStation(port)
        try:
            gcs.connect()
            runs = [fetch(gcs) for _ in range(args.rounds)]
        finally:
            gcs.close()
            proc.send_signal(signal.SIGTERM)
            proc.wait(timeout=20)
            cleanup_namespace(namespace)
    times = sorted(r[0] for r in runs)
    _, general, params, count = runs[0]
    packets = sum(-(-n // 239) for n in (general, params))
    print(f"general metadata {general} B, parameter metadata {params} B ({count} parameters)")
    print(f"FTP data packets per download: {packets}")
    print(f"request to both files parsed: median {times[len(times) // 2] * 1000:.0f} ms, "
          f"worst {times[-1] * 1000:.0f} ms over {len(times)} rounds")  # fmt: skip


if __name__ == "__main__":
    main()
