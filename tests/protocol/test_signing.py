"""Signing per endpoint: required rejects unsigned/forged/replayed writes, signed ones work."""

from __future__ import annotations

import hashlib
import secrets
import time

import pytest
from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import FAKE_NAV, link, plugin, vehicle_config
from tests.support.vehicle import wait_for


def signed_vehicle(port: int, key: str, scheme: str = "udpin") -> str:
    endpoint = f"{scheme}://127.0.0.1:{port}?signing=required"
    return vehicle_config("signed", link(endpoint, signing_key=key), plugin("nav", FAKE_NAV))


PASSPHRASE = "monash clayton 2006"


def no_ack(gcs: GroundStation, command: int, wait_s: float = 1.0) -> bool:
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        if gcs.conn.recv_match(type="COMMAND_ACK", blocking=True, timeout=0.1):
            return False
    return True


@pytest.fixture
def signed(vehicle_factory):
    port = free_udp_port()
    vehicle = vehicle_factory(signed_vehicle(port, PASSPHRASE))
    yield vehicle, port


def test_without_the_key_the_aircraft_is_visible_but_commands_are_refused(signed):
    vehicle, port = signed
    gcs = GroundStation(port)
    heartbeat = gcs.connect()
    assert heartbeat.get_msgbuf()[2] & m.MAVLINK_IFLAG_SIGNED, "the vehicle signs what it sends"
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    assert no_ack(gcs, m.MAV_CMD_REQUEST_MESSAGE)
    wait_for(lambda: vehicle.row("link").frames_bad >= 1, 5, "the rejection counted")
    gcs.close()


def test_with_the_key_commands_work_and_a_replay_is_rejected(signed):
    _, port = signed
    gcs = GroundStation(port)
    key = hashlib.sha256(PASSPHRASE.encode()).digest()
    gcs.conn.setup_signing(key, sign_outgoing=True)
    gcs.connect()
    sent: list[bytes] = []
    original_write = gcs.conn.write

    def capture(buf: bytes) -> None:
        sent.append(bytes(buf))
        original_write(buf)

    gcs.conn.write = capture
    gcs.mav.file = gcs.conn
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    ack = gcs.ack(m.MAV_CMD_REQUEST_MESSAGE)
    assert ack.result == m.MAV_RESULT_ACCEPTED
    command_frame = next(b for b in sent if b[7:10] == bytes([76, 0, 0]))  # COMMAND_LONG
    original_write(command_frame)  # the same signed frame again: a replay
    assert no_ack(gcs, m.MAV_CMD_REQUEST_MESSAGE)


def test_wrong_key_is_rejected(signed):
    _, port = signed
    gcs = GroundStation(port)
    gcs.conn.setup_signing(hashlib.sha256(b"not the key").digest(), sign_outgoing=True)
    gcs.heartbeat()  # its own parser rejects the vehicle's frames: it cannot "connect"
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    assert no_ack(gcs, m.MAV_CMD_REQUEST_MESSAGE)


def test_required_signing_without_a_key_is_a_config_error(tmp_path):
    from companion.exec_control.config import ConfigError, load_config

    path = tmp_path / "v.toml"
    path.write_text(signed_vehicle(14999, ""))
    with pytest.raises(ConfigError, match="asks for signing but signing_key is empty"):
        load_config(path)
    path.write_text(signed_vehicle(14999, PASSPHRASE, scheme="udpp"))
    with pytest.raises(ConfigError, match="expected udpout://HOST:PORT"):
        load_config(path)


def test_a_key_file_made_as_the_hardware_guide_says_matches_mavproxy_typed_the_same_text(
    vehicle_factory, tmp_path
):
    from MAVProxy.modules.mavproxy_signing import SigningModule

    text = secrets.token_hex(32)  # `openssl rand -hex 32 > /etc/companion/signing.key`
    key_file = tmp_path / "signing.key"
    key_file.write_text(text + "\n")
    port = free_udp_port()
    endpoint = f"udpin://127.0.0.1:{port}?signing=required"
    vehicle_factory(
        vehicle_config(
            "signed", link(endpoint, signing_key_file=str(key_file)), plugin("nav", FAKE_NAV)
        )
    )
    gcs = GroundStation(port)
    # What MAVProxy's `signing key TEXT` makes of the text (QGroundControl hashes it alike).
    gcs.conn.setup_signing(SigningModule.passphrase_to_key(None, text), sign_outgoing=True)
    gcs.connect()
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    assert gcs.ack(m.MAV_CMD_REQUEST_MESSAGE).result == m.MAV_RESULT_ACCEPTED
    gcs.close()
