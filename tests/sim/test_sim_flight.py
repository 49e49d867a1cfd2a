"""``companion sim`` in lockstep: the whole vehicle on JSBSim, seen over MAVLink."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil
from pyulog import ULog

from companion.navigation.estimate_csv import read_estimate as read_truth
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import finish, start_sim
from tests.support.vehicle import REPO

EARTH_RADIUS_M = 6378137.0


def horizontal_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    north = math.radians(lat2 - lat1) * EARTH_RADIUS_M
    east = math.radians(lon2 - lon1) * EARTH_RADIUS_M * math.cos(math.radians(lat1))
    return math.hypot(north, east)


def listen(port: int):
    conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255)
    return conn


def collect(conn, into: list) -> None:
    msg = conn.recv_match(type=["GLOBAL_POSITION_INT", "HEARTBEAT"], blocking=True, timeout=0.2)
    if msg is not None:
        into.append(msg)


@pytest.mark.timeout(240)
def test_sixty_seconds_airborne_in_lockstep(tmp_path):
    port = free_udp_port()
    conn = listen(port)
    proc, namespace, truth_path = start_sim(
        tmp_path, f"udpout://127.0.0.1:{port}", "--airborne", "--duration", "60", "--seed", "7"
    )
    seen: list = []
    while proc.poll() is None:
        collect(conn, seen)
    out = finish(proc, namespace, 60)
    conn.close()

    truth = read_truth(truth_path)
    t = np.array(truth["t"])
    # One row per physics frame (100 Hz) for the whole run, and the run lasted 60 s.
    assert len(t) == 6000 and t[-1] == pytest.approx(60.0)
    assert np.allclose(np.diff(t), 0.01, atol=1e-6)
    # Physically plausible: a trimmed Cessna at cruise holds speed and height, and the
    # positions follow from the velocities.
    speed = np.hypot(np.array(truth["vn"]), np.array(truth["ve"]))
    assert speed.min() > 40 and speed.max() < 65
    alt = np.array(truth["alt"])
    assert np.ptp(alt) < 50 and np.all(np.isfinite(alt))
    lat, lon = np.array(truth["lat"]), np.array(truth["lon"])
    travelled = horizontal_m(lat[0], lon[0], lat[-1], lon[-1])
    assert travelled == pytest.approx(speed.mean() * 60, rel=0.05)
    assert np.all(np.abs(np.array(truth["roll"])) < math.radians(30))

    # Over MAVLink the vehicle is seen, and where it says it is, it is.
    heartbeats = [m for m in seen if m.get_type() == "HEARTBEAT"]
    assert heartbeats and heartbeats[0].type == mavutil.mavlink.MAV_TYPE_FIXED_WING
    # From 10 s on: the in-flight alignment has converged. (Before it, one CI run saw 16 m
    # at 7.2 s where quiet runs see at most 4 m: lockstep waits for the drivers, not for the
    # navigator, so a navigator starved of CPU early on lags in simulated time.)
    positions = [
        m for m in seen if m.get_type() == "GLOBAL_POSITION_INT" and m.time_boot_ms > 10_000
    ]
    assert positions, out
    for msg in positions:
        k = int(np.searchsorted(t, msg.time_boot_ms / 1000.0))
        k = min(k, len(t) - 1)
        error = horizontal_m(lat[k], lon[k], msg.lat / 1e7, msg.lon / 1e7)
        assert error < 15.0, (msg.time_boot_ms, error)
    assert "lockstep stalls 0" in out, [line for line in out.splitlines() if "stalls" in line]


@pytest.mark.timeout(240)
def test_the_cub_waits_on_the_runway(tmp_path):
    port = free_udp_port()
    proc, namespace, truth_path = start_sim(
        tmp_path, f"udpout://127.0.0.1:{port}", "--aircraft", "J3Cub", "--duration", "10"
    )
    finish(proc, namespace, 120)
    truth = read_truth(truth_path)
    speed = np.hypot(np.array(truth["vn"]), np.array(truth["ve"]))
    assert len(truth["t"]) == 1000
    assert speed.max() < 3.0, "engine idling, no brakes: it may creep, not fly"
    # On the ground at home: Monash Clayton, the runway 80 m above sea level.
    assert truth["lat"][-1] == pytest.approx(-37.9105, abs=1e-4)
    assert truth["alt"][-1] == pytest.approx(80.0, abs=3.0)


@pytest.mark.timeout(300)
def test_a_config_naming_the_cub_flies_it_in_every_plug_in(tmp_path):
    """``[vehicle] airframe = "J3Cub"`` and no ``--aircraft``: JSBSim flies the Cub, the
    controller its gains and speeds, the servo card its channel map, the log names it."""
    shipped = (REPO / "companion" / "configs" / "sim.toml").read_text()
    assert 'airframe = "c172p"' in shipped
    config = tmp_path / "cub.toml"
    config.write_text(shipped.replace('airframe = "c172p"', 'airframe = "J3Cub"'))
    proc, namespace, truth_path = start_sim(
        tmp_path, f"udpout://127.0.0.1:{free_udp_port()}", "--config", str(config),
        "--plan", str(REPO / "qgc_plans" / "square.plan"), "--airborne", "--start-at", "2",
        "--exact", "--duration", "60",
    )  # fmt: skip
    out = finish(proc, namespace, 240)
    truth = read_truth(truth_path)
    speed = np.hypot(np.array(truth["vn"]), np.array(truth["ve"]))
    alt = np.array(truth["alt"])
    # Started at the Cub's cruise (31 m/s; the Cessna's is 51), then armed on the mission
    # and flown at its AIRSPEED_CRUISE (26; the Cessna's 36) up to the plan's 100 m above
    # home (where it armed, in the air) within the bank limit: the surfaces move as the
    # Cub's servo map says.
    assert speed[0] == pytest.approx(31.0, abs=2.0), out[-2000:]
    assert 20.0 < speed[-2000:].mean() < 30.0, out[-2000:]
    assert alt[-1] - alt[0] == pytest.approx(100.0, abs=15.0), out[-2000:]
    assert np.all(np.abs(np.array(truth["roll"])) < math.radians(50))
    ulog = ULog(str(truth_path.with_suffix(".ulg")))
    assert ulog.msg_info_dict["airframe"] == "J3Cub"
    initial = ulog.initial_parameters
    assert initial["AIRSPEED_CRUISE"] == pytest.approx(26.0)
