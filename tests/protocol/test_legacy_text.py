"""``companion bridge legacy-text`` between a real pty and a running vehicle.

The vehicle replays a recorded flight (GPS and compass through nav.gps_compass) and speaks
MAVLink on two loopback endpoints: one for the bridge, one for this test's ground station,
which is how the test knows what the vehicle said. The old ground station is the pty's
master side: it reads 25-byte frames and writes START and STOP.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from companion.control.modes import MODES, FlightMode
from companion.testing.bench import write_circle_log
from mavlink_dialect import companion as d
from tests.protocol.mav_client import GroundStation, free_udp_port, upload_mission
from tests.support.configs import PluginEntry, flight_group, link, plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import REPO, companion_env, wait_for

FRAME = 25
ARMED = d.MAV_MODE_FLAG_SAFETY_ARMED
MISSION_MODES = {m.px4 for m in MODES if m.mode == FlightMode.MISSION} | {
    m.arduplane for m in MODES if m.mode == FlightMode.MISSION
}


def legacy_vehicle(
    state: Path, log: Path, bridge_port: int, gcs_port: int, *more: PluginEntry
) -> str:
    """A replayed flight, the GPS-compass navigator, the commander, and a link for each side.

    Its pre-arm checks are off, as on a bench: the replayed samples keep the log's time
    stamps, which are not the vehicle clock's, so none would ever look fresh."""
    (state / "params.json").write_text('{"ARMING_CHECK": 0}')
    return vehicle_config(
        "legacy",
        link(f"udpin://127.0.0.1:{bridge_port}", f"udpin://127.0.0.1:{gcs_port}"),
        plugin("replay", "sensors.replay", file=log, speed=1.0, loop=True),
        plugin("nav", "nav.gps_compass"),
        plugin("commander", "vehicle.commander"),
        flight_group(),
        *more,
        sysid=1,
        state_dir=state,
    )


def write_flight_log(path: Path, seconds: float = 120.0) -> None:
    """A circle at 20 m/s: compass at 20 Hz (rolling, pitching, turning through north and
    through negative angles), GPS at 5 Hz: the plug-in's bench vehicle's log."""
    write_circle_log(path, seconds)


class OldGroundStation:
    """The pty's master side: the 2006 ground station."""

    def __init__(self, pty: Pty) -> None:
        self.pty = pty
        os.set_blocking(pty.master, False)
        self.stream = b""

    def read(self) -> None:
        try:
            while chunk := os.read(self.pty.master, 4096):
                self.stream += chunk
        except BlockingIOError:
            pass

    def frames(self) -> list[bytes]:
        whole = len(self.stream) // FRAME * FRAME
        return [self.stream[i : i + FRAME] for i in range(0, whole, FRAME)]

    def send(self, data: bytes) -> None:
        os.write(self.pty.master, data)


class Bridge:
    """``companion bridge legacy-text`` as its own process, as a user would start it."""

    def __init__(self, serial: Path, port: int, *extra: str) -> None:
        args = ["--serial", str(serial), "--mavlink", f"udpout://127.0.0.1:{port}", *extra]
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "companion", "bridge", "legacy-text", *args],
            env=companion_env("unused"),
            cwd=REPO,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.log = ""

    def stop(self) -> str:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        out = self.proc.stdout
        if out is not None and not out.closed:
            self.log += out.read()
            out.close()
        return self.log


@pytest.fixture
def setup(vehicle_factory, tmp_path):
    log = tmp_path / "flight.csv"
    write_flight_log(log)
    bridge_port, gcs_port = free_udp_port(), free_udp_port()
    config = legacy_vehicle(tmp_path, log, bridge_port, gcs_port)
    vehicle_factory(config)
    gcs = GroundStation(gcs_port)
    gcs.connect(timeout_s=30)
    pty = Pty(tmp_path / "ttyRadio")
    made: list[Bridge] = []

    def start_bridge(*extra: str) -> Bridge:
        made.append(Bridge(pty.link, bridge_port, *extra))
        return made[-1]

    yield gcs, OldGroundStation(pty), start_bridge
    for bridge in made:
        bridge.stop()
    gcs.close()


def att_of(msg) -> str:
    roll, pitch, yaw = (math.degrees(a) for a in (msg.roll, msg.pitch, msg.yaw))
    heading = f"{yaw % 360.0:.1f}"
    return f"ATT {roll:.1f} {pitch:.1f} {'0.0' if heading == '360.0' else heading}"


def pos_of(msg) -> str:
    return f"POS {msg.lon / 1e7:.4f} {msg.lat / 1e7:.4f}"


def texts(frames: list[bytes]) -> list[str]:
    out = []
    for frame in frames:
        text, nul, padding = frame.partition(b"\x00")
        assert nul and padding == b"\x00" * len(padding), f"not a NUL-padded frame: {frame!r}"
        out.append(text.decode("ascii"))
    return out


def test_att_and_pos_frames_carry_the_vehicles_telemetry(setup):
    gcs, station, start_bridge = setup
    for msg_id in (d.MAVLINK_MSG_ID_ATTITUDE, d.MAVLINK_MSG_ID_GLOBAL_POSITION_INT):
        gcs.command(d.MAV_CMD_SET_MESSAGE_INTERVAL, msg_id, 10_000)  # every sample, 100 Hz
    start_bridge("--att-rate", "10", "--pos-rate", "4")
    said: set[str] = set()

    def listen() -> None:
        while (msg := gcs.conn.recv_match(type=["ATTITUDE", "GLOBAL_POSITION_INT"])) is not None:
            said.add(att_of(msg) if msg.get_type() == "ATTITUDE" else pos_of(msg))
        station.read()

    wait_for(lambda: listen() or len(station.frames()) >= 5, 30, "the first frames")
    station.stream = station.stream[len(station.stream) // FRAME * FRAME :]
    t0 = time.monotonic()  # from here on every frame is checked
    while time.monotonic() - t0 < 6.0:
        listen()
        time.sleep(0.01)
    window = time.monotonic() - t0
    time.sleep(0.2)  # what was said before the end has arrived
    listen()
    got = texts(station.frames())
    att = [t for t in got if t.startswith("ATT ")]
    pos = [t for t in got if t.startswith("POS ")]
    assert len(att) + len(pos) == len(got)
    assert len(att) == pytest.approx(10 * window, abs=4)  # 10 Hz
    assert len(pos) == pytest.approx(4 * window, abs=3)  # 4 Hz
    # A moving aircraft, fresh values (four decimals of a degree are ~11 m: 120 m flown)
    assert len(set(att)) >= 40 and len(set(pos)) >= 8
    assert [t for t in att + pos if t not in said] == []
    headings = [float(t.split()[3]) for t in att]
    assert all(0.0 <= h < 360.0 for h in headings)


def test_start_arms_and_stop_disarms_through_noise_and_split_frames(setup):
    gcs, station, start_bridge = setup
    bridge = start_bridge()
    wait_for(lambda: station.read() or station.frames(), 30, "the bridge is up")
    station.send(b"START".ljust(FRAME, b"\x00"))
    wait_for(lambda: armed(gcs), 10, "armed after START")
    # Line noise, an unknown message and an over-long one, then STOP in three pieces.
    station.send(b"\xff\x93\x01\x00" + b"HELLO".ljust(FRAME, b"\x00") + b"X" * 40 + b"\x00")
    stop = b"STOP".ljust(FRAME, b"\x00")
    for piece in (stop[:2], stop[2:7], stop[7:]):
        station.send(piece)
        time.sleep(0.05)
    wait_for(lambda: not armed(gcs), 10, "disarmed after STOP")
    log = bridge.stop()
    assert "START: arm -> MAV_RESULT_ACCEPTED" in log
    assert "STOP: disarm -> MAV_RESULT_ACCEPTED" in log
    assert "up 2 commands, 1 unknown, 1 over-long, 0 partial, 3 noise bytes" in log


def test_start_can_also_start_the_mission(setup):
    gcs, station, start_bridge = setup
    upload_mission(gcs)
    start_bridge("--start-mission")
    wait_for(lambda: station.read() or station.frames(), 30, "the bridge is up")
    station.send(b"START".ljust(FRAME, b"\x00"))
    # The mode shows at once; the armed bit once the flight plug-ins run, a moment later.
    wait_for(
        lambda: (b := heartbeat(gcs)) and b.custom_mode in MISSION_MODES and b.base_mode & ARMED,
        10,
        "armed and flying the mission",
    )


def test_the_radio_may_vanish_and_come_back(setup, tmp_path):
    gcs, station, start_bridge = setup
    bridge = start_bridge()
    wait_for(lambda: station.read() or station.frames(), 30, "frames")
    station.pty.vanish()
    time.sleep(0.5)
    again = OldGroundStation(Pty(station.pty.link))
    wait_for(lambda: again.read() or len(again.frames()) >= 5, 10, "frames after the reopen")
    again.send(b"START".ljust(FRAME, b"\x00"))
    wait_for(lambda: armed(gcs), 10, "armed through the new line")
    assert "device reopened 1" in bridge.stop()


def heartbeat(gcs: GroundStation):
    """The vehicle's next heartbeat (the bridge's own, forwarded by the vehicle, skipped)."""
    gcs.heartbeat()
    deadline = time.monotonic() + 2.0
    while time.monotonic() < deadline:
        beat = gcs.conn.recv_match(type="HEARTBEAT", blocking=True, timeout=0.3)
        if beat is not None and beat.get_srcSystem() == 1:
            return beat
    return None


def armed(gcs: GroundStation) -> bool:
    beat = heartbeat(gcs)
    return beat is not None and bool(beat.base_mode & ARMED)


def test_the_vehicle_config_can_start_the_bridge_as_a_plug_in(vehicle_factory, tmp_path):
    # The same bridge, started and supervised by the execution control with the vehicle.
    log = tmp_path / "flight.csv"
    write_flight_log(log)
    bridge_port, gcs_port = free_udp_port(), free_udp_port()
    pty = Pty(tmp_path / "ttyRadio")
    bridge = plugin(
        "legacy",
        "bridge.legacy_text",
        serial=pty.link,
        mavlink=f"udpout://127.0.0.1:{bridge_port}",
    )
    vehicle = vehicle_factory(legacy_vehicle(tmp_path, log, bridge_port, gcs_port, bridge))
    gcs = GroundStation(gcs_port)
    gcs.connect(timeout_s=30)
    station = OldGroundStation(pty)
    try:
        wait_for(lambda: station.read() or len(station.frames()) >= 3, 30, "ATT/POS frames")
        assert {t.split()[0] for t in texts(station.frames())} <= {"ATT", "POS"}
        station.send(b"START".ljust(FRAME, b"\x00"))
        wait_for(lambda: armed(gcs), 10, "armed after START")
        station.send(b"STOP".ljust(FRAME, b"\x00"))
        wait_for(lambda: not armed(gcs), 10, "disarmed after STOP")
        # In the health table like any plug-in (the table is refreshed once a second).
        wait_for(lambda: vehicle.row("legacy").frames_ok >= 5, 10, "the bridge's counts")
        assert vehicle.row("legacy").pid > 0
    finally:
        gcs.close()
