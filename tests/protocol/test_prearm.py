"""Pre-arm checks over MAVLink: refused with ``PreArm: reason`` and DENIED, as ArduPilot.

Each vehicle is real (``companion run``, the real link, commander and supervisor) with a
stand-in navigator and GPS whose state the test chooses; the servo plug-in is the real
Mini SSC II driver, pointed at a device that does or does not exist.
"""

from __future__ import annotations

import json
import time

import pytest

from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import FAKE_GPS, FAKE_NAV, link, plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for

m = pytest.importorskip("mavlink_dialect.companion")

ARM = m.MAV_CMD_COMPONENT_ARM_DISARM


def _vehicle(vehicle_factory, tmp_path, servo: str, aligning=False, fix_type=3, checks=None):
    port = free_udp_port()
    state = tmp_path / "state"
    state.mkdir(exist_ok=True)
    if checks is not None:  # as a bench user would have stored it
        (state / "params.json").write_text(json.dumps({"ARMING_CHECK": checks}))
    vehicle = vehicle_factory(
        vehicle_config(
            "prearm",
            link(f"udpin://127.0.0.1:{port}"),
            plugin("nav", FAKE_NAV, aligning=aligning),
            plugin("gps", FAKE_GPS, fix_type=fix_type),
            plugin("commander", "vehicle.commander"),
            plugin("servos", "actuators.minissc", group="flight", device=servo),
            state_dir=state,
        )
    )
    gcs = GroundStation(port)
    gcs.connect()
    # The test's own reader of the health table may not have had one yet (None): waited for.
    vehicle.wait_running("gps")
    vehicle.wait_running("nav")
    # Running is not yet publishing on a busy machine: the checks judge what nav/state says.
    nav = vehicle.bus.latest_reader("nav/state")
    wait_for(nav.get, 60, "the navigator's first solution")
    # ... and the link's reader may join later still: NAV_STATUS says the link has it.
    gcs.recv("NAV_STATUS", 60)
    return vehicle, gcs


def _arm(gcs: GroundStation, *params: float) -> tuple[int, list[str]]:
    """The arm command's result and the PreArm texts that came with it (a long one put
    together from its STATUSTEXT chunks, as QGroundControl does)."""
    while gcs.conn.recv_match(type="STATUSTEXT", blocking=False) is not None:
        pass
    gcs.command(ARM, 1, *params)
    result, texts, chunked = None, [], {}
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type=["COMMAND_ACK", "STATUSTEXT"], blocking=True, timeout=1.0)
        if msg is None:
            if result is not None:
                break  # a quiet second after the ack: every text has come
            continue
        if msg.get_type() == "STATUSTEXT" and msg.id:
            chunked.setdefault(msg.id, []).append((msg.chunk_seq, msg.text))
        elif msg.get_type() == "STATUSTEXT":
            texts.append(msg.text)
        elif msg.command == ARM:
            result = msg.result
    assert result is not None, "no COMMAND_ACK for the arm command"
    texts += ["".join(text for _, text in sorted(parts)) for parts in chunked.values()]
    return result, [t for t in texts if t.startswith("PreArm: ")]


def _ready_bit(gcs: GroundStation) -> bool:
    status = gcs.recv("SYS_STATUS", 5)
    assert status.onboard_control_sensors_present & m.MAV_SYS_STATUS_PREARM_CHECK
    return bool(status.onboard_control_sensors_health & m.MAV_SYS_STATUS_PREARM_CHECK)


@pytest.fixture
def servo_pty(tmp_path):
    pty = Pty(tmp_path / "ttyServo")
    yield str(pty.link)
    pty.vanish()


def test_no_gps_fix_is_refused_with_its_reason_then_force_arms(
    vehicle_factory, tmp_path, servo_pty
):
    vehicle, gcs = _vehicle(vehicle_factory, tmp_path, servo_pty, fix_type=1)
    wait_for(lambda: not _ready_bit(gcs), 10, "SYS_STATUS says not ready")
    result, texts = _arm(gcs)
    assert result == m.MAV_RESULT_DENIED
    assert "PreArm: GPS: no 3D fix" in texts
    assert vehicle.row("servos").pid == 0
    result, _ = _arm(gcs, 21196)  # forced, as ArduPilot and PX4
    assert result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: vehicle.row("servos").pid, 10, "flight group running")
    gcs.close()


def test_navigation_still_aligning_is_refused(vehicle_factory, tmp_path, servo_pty):
    _, gcs = _vehicle(vehicle_factory, tmp_path, servo_pty, aligning=True)
    result, texts = _arm(gcs)
    assert result == m.MAV_RESULT_DENIED
    assert "PreArm: navigation still aligning" in texts
    gcs.close()


def test_missing_servo_device_is_refused(vehicle_factory, tmp_path):
    vehicle, gcs = _vehicle(vehicle_factory, tmp_path, str(tmp_path / "no-such-tty"))
    wait_for(lambda: _ready_bit(gcs), 10, "SYS_STATUS says ready (the servo is checked on arming)")
    result, texts = _arm(gcs)
    assert result == m.MAV_RESULT_DENIED
    # Whole, well past the 48 bytes an ack once carried: the error and the device.
    whole = [t for t in texts if t.startswith("PreArm: servo device: ")]
    assert whole and whole[0].startswith("PreArm: servo device: [Errno 2] No such file"), texts
    assert whole[0].endswith("no-such-tty'") and len(whole[0]) > 100, texts
    assert vehicle.row("servos").pid == 0
    gcs.close()


def test_a_ready_vehicle_arms_and_checks_can_be_turned_off(vehicle_factory, tmp_path, servo_pty):
    _, gcs = _vehicle(vehicle_factory, tmp_path, servo_pty)
    wait_for(lambda: _ready_bit(gcs), 10, "SYS_STATUS says ready")
    assert _arm(gcs) == (m.MAV_RESULT_ACCEPTED, [])
    gcs.close()


def test_with_checks_disabled_an_unready_vehicle_arms(vehicle_factory, tmp_path):
    missing = str(tmp_path / "no-such-tty")
    vehicle, gcs = _vehicle(vehicle_factory, tmp_path, missing, aligning=True, fix_type=0, checks=0)
    result, texts = _arm(gcs)
    assert (result, texts) == (m.MAV_RESULT_ACCEPTED, [])
    wait_for(lambda: vehicle.row("servos").pid, 10, "flight group running")
    gcs.close()
