"""Analyze Tools → MAVLink Console against a real vehicle, as QGroundControl 4.4 and 5 use it.

QGroundControl's MAVLinkConsoleController sends each line typed, newline included, as
SERIAL_CONTROL to the SHELL device with RESPOND | EXCLUSIVE | MULTI (data padded to 70
bytes, ``count`` the bytes that are the line), and shows every SERIAL_CONTROL the vehicle
sends back as a terminal would; closing the page sends an empty one without RESPOND. PX4's
``mavlink_shell.py`` sends keystrokes one by one and expects them echoed. Before, the
console answered nothing: issue 42 found it "offered and answers nothing".
"""

from __future__ import annotations

import struct
import time

import pytest

from companion.link.shell_service import PROMPT
from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, connected_station
from tests.support.configs import client_vehicle

QGC_FLAGS = (
    m.SERIAL_CONTROL_FLAG_RESPOND | m.SERIAL_CONTROL_FLAG_EXCLUSIVE | m.SERIAL_CONTROL_FLAG_MULTI
)


@pytest.fixture
def gcs(vehicle_factory, tmp_path):
    state = tmp_path / "state"
    yield from connected_station(vehicle_factory, lambda url: client_vehicle(url, state))


def _send(gcs: GroundStation, data: bytes, flags: int = QGC_FLAGS, device: int = 0) -> None:
    """As QGroundControl's MAVLink library frames it: the 79 bytes of the definition the
    vehicle has, then target_system and target_component, extension fields of a newer one
    (81 bytes; refused as too long, the console once got nothing)."""
    device = device or m.SERIAL_CONTROL_DEV_SHELL
    msg = gcs.mav.serial_control_encode(device, flags, 0, 0, len(data), data.ljust(70, b"\0"))
    payload = struct.pack("<IHBBB70s", 0, 0, device, flags, len(data), data) + b"\x01\x01"
    seq = gcs.mav.seq
    gcs.mav.seq = (seq + 1) % 256
    head = struct.pack("<BBBBBBBHB", 0xFD, len(payload), 0, 0, seq, 255, 190, msg.id, 0)
    crc = m.x25crc(head[1:] + payload + bytes([msg.crc_extra])).crc
    gcs.conn.write(head + payload + struct.pack("<H", crc))


def _read(gcs: GroundStation, prompts: int, timeout_s: float = 10.0) -> str:
    """What the console shows, until ``prompts`` prompts have come (or the time is up)."""
    text, end = "", time.monotonic() + timeout_s
    while text.count(PROMPT) < prompts and time.monotonic() < end:
        msg = gcs.conn.recv_match(type="SERIAL_CONTROL", blocking=True, timeout=0.5)
        if msg is None or msg.get_srcSystem() != 1:
            continue
        assert msg.device == m.SERIAL_CONTROL_DEV_SHELL
        assert msg.flags & m.SERIAL_CONTROL_FLAG_REPLY
        text += bytes(msg.data[: msg.count]).decode("ascii")
    return text


def _top(gcs: GroundStation, timeout_s: float = 20.0) -> str:
    """``top`` as a person types it again while the vehicle has just started: the supervisor's
    first health table can come a second or more after the first HEARTBEAT on a busy machine."""
    end = time.monotonic() + timeout_s
    while True:
        _send(gcs, b"top\n")
        table = _read(gcs, 1)
        if "no health table yet" not in table or time.monotonic() > end:
            return table
        time.sleep(0.5)


def test_qgroundcontrols_console_gets_the_plug_ins_the_versions_and_the_parameters(gcs):
    _send(gcs, b"help\n")
    shown = _read(gcs, 2)
    assert shown.startswith(f"{PROMPT}help\n") and shown.endswith(PROMPT), shown
    assert all(f"  {name}" in shown for name in ("help", "ver", "top", "param")), shown
    # The plug-ins as `companion status` shows them: each running, with its process id.
    table = _top(gcs)
    assert table.startswith("top\nsupervisor pid "), table
    rows = {line.split()[0]: line.split() for line in table.splitlines()[2:-1]}
    core = {"link", "nav", "gps", "commander"}
    assert all(rows[n][1] == "running" and int(rows[n][2]) > 0 for n in core), table
    assert rows["flight"][1:3] == ["stopped", "-"], table  # disarmed: the flight group is not
    # A parameter's value is the one the Parameters page reads.
    gcs.mav.param_request_read_send(1, 1, b"SYS_AUTOSTART", -1)
    value = gcs.recv("PARAM_VALUE", 5.0, param_id="SYS_AUTOSTART").param_value
    _send(gcs, b"param show sys_autost*\n")
    shown = _read(gcs, 1)
    assert f"SYS_AUTOSTART: {value:g}\n" in shown, shown
    assert "1 of " in shown, shown
    _send(gcs, b"ver\n")
    assert "follows PX4 1.15.0" in _read(gcs, 1)
    _send(gcs, b"reboot\n")  # nothing typed here changes the vehicle
    assert "reboot: command not found" in _read(gcs, 1)


def test_keystrokes_are_echoed_as_mavlink_shell_py_expects(gcs):
    for key in b"vex\x7fr\n":  # a typo rubbed out
        _send(gcs, bytes([key]))
    shown = _read(gcs, 2)
    assert shown.startswith(f"{PROMPT}vex\b \br\ncompanion "), shown


def test_hostile_input_is_dropped_and_the_console_goes_on(gcs):
    _send(gcs, b"top\n", device=m.SERIAL_CONTROL_DEV_GPS1)  # a port it does not hand out
    _send(gcs, b"top\n", flags=m.SERIAL_CONTROL_FLAG_REPLY | QGC_FLAGS)  # a stray reply
    assert _read(gcs, 1, 2.0) == ""
    _send(gcs, bytes([0, 1, 7, 0x1B, 0x9B, 0xFF]) + bytes(range(0x80, 0xC0)))  # not echoed
    for _ in range(4):
        _send(gcs, b"x" * 70)  # a line past its 200 characters is cut there
    _send(gcs, b"\n")
    shown = _read(gcs, 2)
    assert f"{'x' * 200}: command not found" in shown and "x" * 201 not in shown, shown
    assert all(0x20 <= ord(c) < 0x7F or c in "\n\b" for c in shown), repr(shown)
    # The page closed (no RESPOND), then opened again: the first answer starts at a prompt.
    _send(gcs, b"", flags=0)
    _send(gcs, b"ver\n")
    assert _read(gcs, 2).startswith(f"{PROMPT}ver\ncompanion ")
