"""A composed plug-in blocked in its device's read stops when its process tells it to."""

from __future__ import annotations

import os
import threading

from companion.exec_control.composed_host import Member
from companion.sensors.serial_port import ReopeningSerial
from tests.support.pty import StreamingPty
from tests.support.vehicle import wait_for


def test_a_composed_sensor_reading_a_live_device_stops_at_once(tmp_path):
    """The read waits on the device and on the plug-in's stop descriptor; the stop wakes it,
    the read takes the stop's byte and returns empty, and the plug-in's loop then ends (on
    a blocking descriptor that read waited for ever for a second byte)."""
    member = Member({"name": "compass"})
    device = StreamingPty(tmp_path / "ttyCOMPASS", lambda i: b"$C1.0P2.0R3.0*00\r\n", 0.05)
    port = ReopeningSerial(str(device.link), 19200, read_timeout_s=5.0, stop_fd=member._stop_r)
    reads: list[bytes] = []

    def sensor() -> None:  # a serial sensor's steps, as its host runs them
        while not member.stopping:
            reads.append(port.read_stamped(lambda: 0)[0])

    thread = threading.Thread(target=sensor, daemon=True)
    device.start()
    try:
        thread.start()
        wait_for(lambda: any(reads), 10.0, "the device's first bytes")
        member.stop()
        thread.join(2.0)
        assert not thread.is_alive(), "the sensor's read never returned after the stop"
    finally:
        device.close()
        port.close()
        os.close(member._stop_w)
        os.close(member._stop_r)
