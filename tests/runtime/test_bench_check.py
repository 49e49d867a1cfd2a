"""``companion check`` against pseudo-terminals standing in for the aircraft's devices.

Good devices (real NMEA, ``$C`` and VectorNav sentences at their rates; a servo card that
reads the neutral frames back) pass with exit status 0. A silent one, one set to another
baud rate (its bytes as a UART at the config's rate would make of them), one spewing text
that is no sentence, one with corrupted checksums and a binary one spewing noise each fail
with exit status 1, named, and with what to look at in plain words.
"""

from __future__ import annotations

import os
import random
import re
import subprocess
import sys
from pathlib import Path

import pytest

from companion.actuators.airframe import load_airframe
from tests.support.configs import plugin, vehicle_config
from tests.support.nmea import gga, rmc
from tests.support.pty import StreamingPty
from tests.support.vehicle import REPO
from tests.support.wrong_baud import heard_at
from tests.unit.sensors.test_os3000 import MANUAL_SHORT
from tests.unit.sensors.test_vectornav import IMU, xor8

VNIMU = f"$VNIMU,{IMU}*{xor8('VNIMU,' + IMU)}\r\n"
COMPASS = MANUAL_SHORT + "\r\n"


def nmea_epoch(second: int) -> str:
    t = f"1200{second % 60:02d}.00"
    return gga(t, -37.9, 145.1, 50.0) + "\r\n" + rmc(t, "021226", -37.9, 145.1, 0.0, 0.0) + "\r\n"


@pytest.fixture
def devices(tmp_path):
    made: list[StreamingPty] = []

    def make(name: str, chunks=None, period_s: float = 0.05) -> StreamingPty:
        device = StreamingPty(tmp_path / name, chunks, period_s)
        device.start()
        made.append(device)
        return device

    yield make
    for device in made:
        device.close()


def check(tmp_path: Path, *plugins: str) -> subprocess.CompletedProcess[str]:
    config = tmp_path / "bench.toml"
    config.write_text(vehicle_config("bench", *plugins))
    cmd = [sys.executable, "-m", "companion", "check", "-c", str(config), "--seconds", "3"]
    return subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=60)


def verdict(out: str, name: str) -> str:
    found = re.search(rf"^(ok  |FAIL) {re.escape(name)}: (.*)$", out, re.M)
    assert found, out
    return found.group(1).strip() + " " + found.group(2)


def row(out: str, name: str) -> list[str]:
    """The table's cells for a plug-in (bytes, frames, bad, rate...)."""
    line = next(x for x in out.splitlines() if re.match(rf"^│ {re.escape(name)} ", x))
    return [cell.strip() for cell in line.strip("│").split("│")]


@pytest.mark.timeout(90)
def test_good_devices_answer_and_the_servo_card_gets_neutral_frames(tmp_path, devices):
    gps = devices("gps", lambda n: nmea_epoch(n).encode(), period_s=1.0)
    compass = devices("compass", lambda n: COMPASS.encode(), period_s=0.05)
    imu = devices("imu", lambda n: VNIMU.encode(), period_s=0.025)
    servos = devices("servos")
    done = check(
        tmp_path,
        plugin("gps", "sensors.nmea_gps", device=gps.link, baud=4800),
        plugin("compass", "sensors.os3000", device=compass.link),
        plugin("imu", "sensors.serial_imu", device=imu.link),
        plugin("servos", "actuators.minissc", group="flight", device=servos.link),
    )
    assert done.returncode == 0, done.stdout + done.stderr
    for name in ("gps", "compass", "imu"):
        assert verdict(done.stdout, name) == "ok answers.", done.stdout
    _, _, _, nbytes, frames, bad, rate, _ = row(done.stdout, "compass")
    assert int(nbytes) > 0 and int(frames) >= 30 and bad == "0"
    measured, expected = re.match(r"([\d.]+)/s of ([\d.]+)/s", rate).groups()
    assert 14 <= float(measured) <= 22 and expected == "20"  # 20 Hz, on a busy machine
    gps_rate = float(row(done.stdout, "gps")[6].split("/")[0])
    assert 0.7 <= gps_rate <= 1.3
    channels = load_airframe("c172p").channels
    assert verdict(done.stdout, "servos").startswith(f"ok sent {len(channels)} neutral frames")
    # What reached the card: every channel once, at the airframe's safe position.
    sent = servos.read_all()
    frames = {sent[i + 1]: sent[i + 2] for i in range(0, len(sent), 3) if sent[i] == 0xFF}
    assert len(sent) == 3 * len(channels)
    assert frames == {c.servo: c.safe for c in channels}


@pytest.mark.timeout(90)
def test_silent_wrong_baud_and_garbage_devices_fail_with_what_to_look_at(tmp_path, devices):
    # A GPS left at 9600 baud while the config says 4800: what the UART makes of it.
    wrong = [heard_at(nmea_epoch(n).encode(), 9600, 4800) for n in range(60)]
    gps = devices("gps", lambda n: wrong[n % 60], period_s=1.0)
    battery = devices("battery")  # plugged in, says nothing
    rng = random.Random(7)
    letters = "abcdefghijklmnopqrstuvwxyz ,.0123456789"
    junk = [("".join(rng.choices(letters, k=60)) + "\r\n").encode() for _ in range(50)]
    imu = devices("imu", lambda n: junk[n % 50], period_s=0.025)
    corrupt = COMPASS.replace("320.5", "321.5")  # a bit flipped on the line, checksum kept
    compass = devices("compass", lambda n: (corrupt if n % 2 else COMPASS).encode())
    noise = devices("range", lambda n: rng.randbytes(64), period_s=0.02)
    done = check(
        tmp_path,
        plugin("gps", "sensors.nmea_gps", device=gps.link, baud=4800),
        plugin("battery", "sensors.battery", device=battery.link),
        plugin("imu", "sensors.serial_imu", device=imu.link),
        plugin("compass", "sensors.os3000", device=compass.link),
        plugin("range", "sensors.rangefinder", device=noise.link),
        plugin("servos", "actuators.minissc", device=tmp_path / "unplugged", group="flight"),
    )
    assert done.returncode == 1, done.stdout + done.stderr
    out = done.stdout
    assert re.match(r"FAIL \d+ bytes, none of them text: the baud rate is wrong \(the config "
                    r"says 4800", verdict(out, "gps"))  # fmt: skip
    assert verdict(out, "battery").startswith("FAIL no bytes in 3 s. Look at the device's power")
    assert "bytes of text, but none of the sentences this plug-in reads" in verdict(out, "imu")
    assert re.match(r"FAIL garbled: \d+ of \d+ frames bad", verdict(out, "compass"))
    assert "no valid frame: a wrong baud rate" in verdict(out, "range")
    assert verdict(out, "servos").startswith("FAIL no such device: is it plugged in")
    assert row(out, "battery")[3:6] == ["0", "0", "0"]  # bytes, frames, bad


@pytest.mark.timeout(90)
def test_a_radio_counts_a_stations_frames_and_may_be_silent_but_its_key_must_be_there(
    tmp_path, devices
):
    from mavlink_dialect import companion as m

    mav = m.MAVLink(None, srcSystem=255, srcComponent=190)  # a ground station's heartbeat
    heartbeat = mav.heartbeat_encode(m.MAV_TYPE_GCS, m.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(mav)
    radio = devices("radio", lambda n: heartbeat, period_s=0.1)
    key = tmp_path / "signing.key"
    signed = f"serial://{radio.link}:57600?signing=required"
    link = plugin("link", "link.mavlink", endpoints=[signed], signing_key_file=key)
    done = check(tmp_path, link)
    assert done.returncode == 1, done.stdout + done.stderr
    assert verdict(done.stdout, "link (radio)") == "ok answers."
    assert int(row(done.stdout, "link (radio)")[4]) >= 15  # frames: 10 a second for 3 s
    assert re.search(r"^FAIL link: signing key file: No such file or directory", done.stdout, re.M)

    key.write_text("ab" * 32 + "\n")
    radio.chunks = None  # the ground station is off: the radio hears nothing
    done = check(tmp_path, link)
    assert done.returncode == 0, done.stdout + done.stderr
    assert verdict(done.stdout, "link (radio)").startswith("ok silent: normal until a ground")


@pytest.mark.timeout(60)
def test_two_plugins_on_one_device_are_refused(tmp_path, devices):
    """Refused with the config, as `companion run` refuses it (companion.exec_control
    .topology): nothing is opened, so neither plug-in takes the other's bytes."""
    shared = devices("shared", lambda n: COMPASS.encode())
    done = check(
        tmp_path,
        plugin("compass", "sensors.os3000", device=shared.link),
        plugin("gps", "sensors.nmea_gps", device=f"serial://{shared.link}:4800"),
    )
    assert done.returncode == 2
    device = os.path.realpath(shared.link)
    assert f"gps: device {device} is compass's too" in " ".join(done.stderr.split())
