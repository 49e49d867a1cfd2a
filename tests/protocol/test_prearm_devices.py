"""A silent or garbled device refuses arming with ``PreArm:`` naming its plug-in.

A real vehicle (link, commander, supervisor) with the real OS-3000 compass driver on a
pty; the navigator and GPS are stand-ins that are ready, so the compass is all that is
judged. The compass is first silent, then sends good ``$C`` sentences at 20 Hz (arming is
accepted), then its bytes come as a UART at the wrong baud rate makes them.
"""

from __future__ import annotations

import pytest

from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.protocol.test_prearm import _arm, _ready_bit
from tests.support.configs import FAKE_GPS, FAKE_NAV, link, plugin, vehicle_config
from tests.support.pty import Pty, StreamingPty
from tests.support.vehicle import wait_for
from tests.support.wrong_baud import heard_at
from tests.unit.sensors.test_os3000 import MANUAL_SHORT

m = pytest.importorskip("mavlink_dialect.companion")

GOOD = (MANUAL_SHORT + "\r\n").encode()
WRONG_BAUD = heard_at(GOOD, 4800, 19200)  # a compass left at 4800, read at 19200


@pytest.mark.timeout(120)
def test_silent_then_good_then_garbled_compass(vehicle_factory, tmp_path):
    compass = StreamingPty(tmp_path / "ttyCompass", None, period_s=0.05).start()
    servos = Pty(tmp_path / "ttyServo")
    port = free_udp_port()
    vehicle = vehicle_factory(
        vehicle_config(
            "prearm_devices",
            link(f"udpin://127.0.0.1:{port}"),
            plugin("nav", FAKE_NAV),
            plugin("gps", FAKE_GPS, fix_type=3),
            plugin("compass", "sensors.os3000", device=compass.link),
            plugin("commander", "vehicle.commander"),
            plugin("servos", "actuators.minissc", group="flight", device=servos.link),
            state_dir=tmp_path / "state",
        )
    )
    gcs = GroundStation(port)
    gcs.connect()
    try:
        wait_for(lambda: vehicle.row("compass").pid, 60, "the compass plug-in running")
        wait_for(lambda: not _ready_bit(gcs), 20, "SYS_STATUS: not ready")
        silent = "PreArm: compass: no data from its device"
        # The verdict on a device takes the watch's window of 3 s from the link's start.
        result, texts = wait_for(lambda: _refused_with(gcs, silent), 30, "silence named")
        assert result == m.MAV_RESULT_DENIED
        assert texts == [silent]

        compass.chunks = lambda n: GOOD
        wait_for(lambda: _ready_bit(gcs), 20, "SYS_STATUS: ready once the compass talks")
        assert _arm(gcs) == (m.MAV_RESULT_ACCEPTED, [])
        _arm_off(gcs)

        compass.chunks = lambda n: WRONG_BAUD
        garbled = "PreArm: compass: garbled data (wrong baud rate?)"
        # No heading at once ("compass not fresh"); the verdict on its bytes takes the
        # watch's window of 3 s.
        result, texts = wait_for(lambda: _refused_with(gcs, garbled), 30, "garbled named")
        assert result == m.MAV_RESULT_DENIED
        assert texts == ["PreArm: compass not fresh", garbled]
        assert vehicle.row("compass").bytes_in > 0  # the health table tells it from silence
    finally:
        gcs.close()
        compass.close()
        servos.vanish()


def _refused_with(gcs: GroundStation, text: str) -> tuple[int, list[str]] | None:
    result, texts = _arm(gcs)
    return (result, texts) if text in texts else None


def _arm_off(gcs: GroundStation) -> None:
    gcs.command(m.MAV_CMD_COMPONENT_ARM_DISARM, 0)
    ack = gcs.recv("COMMAND_ACK", 10)
    assert ack.result == m.MAV_RESULT_ACCEPTED
