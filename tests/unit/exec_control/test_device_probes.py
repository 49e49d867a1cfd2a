"""Every device plug-in names its device for ``companion check``, with a stream that counts
its frames as the vehicle's driver does: good frames accepted, corrupted ones refused."""

from __future__ import annotations

import pytest

from companion.exec_control.registry import load
from tests.support import sbus, tfmini
from tests.support.nmea import gga, rmc
from tests.unit.sensors.test_battery_monitor import sentence as pcbat
from tests.unit.sensors.test_os3000 import MANUAL_SHORT
from tests.unit.sensors.test_vectornav import IMU, xor8


def settings_of(kind: str, **given) -> dict:
    """The plug-in's settings, defaults filled in as the config check does."""
    return {name: s.default for name, s in load(kind).settings.items()} | given


def epoch(second: int) -> bytes:
    t = f"1200{second:02d}.00"
    return (
        gga(t, -37.9, 145.1, 50.0) + "\r\n" + rmc(t, "021226", -37.9, 145.1, 0, 0) + "\r\n"
    ).encode()


GOOD = {
    "sensors.nmea_gps": b"".join(epoch(s) for s in range(3)) + epoch(3)[:10],
    "sensors.os3000": (MANUAL_SHORT + "\r\n").encode() * 3,
    "sensors.serial_imu": f"$VNIMU,{IMU}*{xor8('VNIMU,' + IMU)}\r\n".encode() * 3,
    "sensors.battery": (pcbat("PCBAT,12384,-250") + b"\r\n") * 3,
    "sensors.rangefinder": tfmini.frame(250) * 3,
    "sensors.rc_input": sbus.frame([992] * 16) * 3,
}


@pytest.mark.parametrize("kind", sorted(GOOD))
def test_each_sensor_probe_decodes_its_own_frames_and_refuses_corrupted_ones(kind):
    (probe,) = load(kind).probe(settings_of(kind, device="/dev/ttyX"))
    assert probe.device == "/dev/ttyX" and probe.rate_hz > 0 and probe.must_answer
    readings = probe.stream.feed(GOOD[kind], 1_000)
    assert len(readings) >= 2 and probe.stream.frames_ok >= 2 and probe.stream.frames_bad == 0
    data = bytearray(GOOD[kind][: len(GOOD[kind]) // 3])
    # One bit flipped inside a frame (SBUS has no checksum: its end byte, then).
    data[-1 if kind == "sensors.rc_input" else len(data) // 2] ^= 0x01
    probe.stream.feed(bytes(data) * 2, 2_000)
    assert probe.stream.frames_bad >= 1


def test_the_servo_card_is_sent_its_safe_positions_and_the_link_its_radios_only():
    (servos,) = load("actuators.minissc").probe(
        settings_of("actuators.minissc", device="/dev/ttyS"), {"airframe": "J3Cub"}
    )
    assert servos.stream is None and len(servos.neutral) == 15  # J3Cub: five channels
    assert servos.neutral[:3] == bytes((0xFF, 0, 10))  # throttle (servo 0) at its minimum
    endpoints = ["udpout://127.0.0.1:14550", "serial:///dev/ttyRadio:57600?signing=required"]
    link = settings_of("link.mavlink", endpoints=endpoints, signing_key="k")
    (radio,) = load("link.mavlink").probe(link)
    assert (radio.device, radio.baud, radio.must_answer) == ("/dev/ttyRadio", 57600, False)
