"""The same exact-lockstep mission flown with one process per plug-in and with the plug-ins
composed into one process (``companion/configs/sim_composed.toml``) is the same flight:
the same seed writes the same truth file, frame for frame, whichever layout flew it. The
one-process-per-plug-in flight also wakes its navigator on every IMU sample (``wake_hz``
0), the composed one once a state (the shipped 50): the navigator's states are the same.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from pyulog import ULog

from companion.navigation.estimate_csv import read_estimate as read_truth
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import finish, start_sim
from tests.support.vehicle import REPO

PLAN = str(REPO / "qgc_plans" / "short_leg.plan")
COMPOSED = str(REPO / "companion" / "configs" / "sim_composed.toml")
ARGS = ("--exact", "--start-at", "5", "--plan", PLAN, "--wind", "3,2,0",
        "--turbulence", "moderate", "--seed", "11", "--duration", "45")  # fmt: skip
# The bridge's summary: every way exact lockstep can let a frame go before the vehicle
# answered it (each would make the flight depend on the machine's load, not the seed).
MISSES = ("lockstep stalls", "control stalls", "nav stalls", "late samples", "late servo bytes")
# Flight-log channels from the sensors to the surfaces that lockstep keeps in step (the
# commander's status goes out on its own time: its stamps differ from run to run).
CHAIN = ("sensors_imu", "sensors_gps", "sensors_compass", "sensors_mag", "sensors_baro",
         "sensors_range", "sensors_rc", "nav_state", "control_actuators")  # fmt: skip


def _fly(tmp_path: Path, name: str, *config: str) -> tuple[Path, str]:
    folder = tmp_path / name
    folder.mkdir()
    link = f"udpout://127.0.0.1:{free_udp_port()}"
    proc, namespace, truth = start_sim(folder, link, *ARGS, *config)
    out = finish(proc, namespace, 600)  # exact lockstep runs at the pace of a busy machine
    assert "START accepted" in out and "MISSION_START accepted" in out, out
    for miss in MISSES:
        counted = re.search(rf"{miss} (\d+)", out)
        assert counted and counted.group(1) == "0", f"{name}: {miss} not 0:\n{out}"
    return truth, out


def _first_difference(a: Path, b: Path) -> str:
    """The first flight-log sample (time stamp, channel) the two flights disagree on."""
    first: tuple[float, str] | None = None
    logs = [{d.name: d.data for d in ULog(str(p), list(CHAIN)).data_list} for p in (a, b)]
    for name in CHAIN:
        x, y = logs[0].get(name, {}), logs[1].get(name, {})
        n = min(len(x.get("timestamp", ())), len(y.get("timestamp", ())))
        for field in x:
            u, v = np.asarray(x[field][:n]), np.asarray(y.get(field, x[field])[:n])
            same = (u == v) | (np.isnan(u) & np.isnan(v)) if u.dtype.kind == "f" else u == v
            if not same.all():
                i = int(np.argmin(same))
                t = float(x["timestamp"][i]) / 1e6
                if first is None or t < first[0]:
                    first = (t, f"{name}.{field}")
    return "none" if first is None else f"{first[1]} at {first[0]:.2f} s"


def _woken_every_sample(tmp_path: Path) -> str:
    """sim.toml with the navigator woken on every IMU sample, not once a state."""
    text = (REPO / "companion" / "configs" / "sim.toml").read_text()
    shipped = (
        'device = "sim://imu", baud = 115200, rate_hz = 100.0, wake_hz = 50.0, read_on_wake = true'
    )
    assert shipped in text, "sim.toml's IMU line changed: update this test"
    path = tmp_path / "every_sample.toml"
    every = 'device = "sim://imu", baud = 115200, rate_hz = 100.0, wake_hz = 0.0'
    path.write_text(text.replace(shipped, every))
    return str(path)


@pytest.mark.timeout(1300)
def test_the_composed_layout_flies_the_same_flight(tmp_path):
    own, _ = _fly(tmp_path, "own_processes", "--config", _woken_every_sample(tmp_path))
    composed, _ = _fly(tmp_path, "composed", "--config", COMPOSED)
    climb = np.array(read_truth(own)["alt"])
    assert climb[-1] - climb[0] > 20, "the aircraft took off"
    rows = [p.read_text().splitlines() for p in (own, composed)]
    if rows[0] != rows[1]:
        parted = next((x.split(",")[0] for x, y in zip(*rows, strict=False) if x != y), "the end")
        first = _first_difference(own.with_suffix(".ulg"), composed.with_suffix(".ulg"))
        pytest.fail(
            f"the layouts flew different flights: the truth parts at t={parted} s; the"
            f" flight logs first differ in {first}"
        )
