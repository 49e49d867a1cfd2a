"""sensors.os3000 on a real pseudo-terminal: attitude and field flow, junk is counted."""

from __future__ import annotations

import itertools
import math
from types import SimpleNamespace

import pytest

from companion.bus.clock import MonotonicClock
from companion.messages import Magnetometer, VehicleStatus
from companion.plugins.sensors.os3000 import Os3000Compass
from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for
from tests.unit.sensors.test_os3000 import sentence


@pytest.mark.timeout(60)
def test_compass_and_magnetometer_from_a_pty(vehicle_factory, tmp_path):
    pty = Pty(tmp_path / "ttyCompass")
    compass_plugin = plugin("compass", "sensors.os3000", device=pty.link)
    vehicle = vehicle_factory(vehicle_config("compass", compass_plugin))
    compass = vehicle.bus.queue_reader("sensors/compass")
    mag = vehicle.bus.queue_reader("sensors/mag")
    vehicle.wait_running("compass")
    got, fields = [], []
    line = sentence("C45.0P2.0R-1.0T21.0Mx200.0My0.0Mz-400.0") + "\r\n"

    def stream() -> bool:
        pty.write(line + "$C1P2*00\r\n" + line)
        got.extend(compass.take(0.3))
        fields.extend(mag.take(0.1))
        return len(got) >= 2 and bool(fields)

    wait_for(stream, 15, "compass readings")
    assert got[0].heading_rad == pytest.approx(math.radians(45.0))
    # The OS-5000's axes are x forward, y left, z up: Mz -400 mG is +0.4 G in body FRD.
    assert fields[0].mz_gauss == pytest.approx(0.4)
    wait_for(lambda: vehicle.row("compass").frames_bad >= 1, 5, "the bad sentence counted")
    pty.vanish()


def _newest_steps(stats, name: bytes) -> int | None:
    """The plug-in's newest step count on system/plugin_stats (once a second), if any came."""
    steps = None
    for s in stats.drain():
        if s.name == name:
            steps = int(s.steps)
    return steps


@pytest.mark.timeout(90)
def test_beside_a_speaking_magnetometer_the_compass_is_read_in_batches_every_frame_kept(
    vehicle_factory, tmp_path
):
    """batch_s: while another magnetometer speaks, the compass is read once a batch (0.2 s)
    rather than once a sentence, and still publishes every sentence, in order, each with a
    time of its own; silent, or the compass itself the magnetometer, its heading is read as
    it comes (``per_frame``)."""
    pty = Pty(tmp_path / "ttyCompass")
    entry = plugin("compass", "sensors.os3000", device=pty.link, rate_hz=20.0, batch_s=0.2)
    vehicle = vehicle_factory(vehicle_config("compass", entry))
    bus = vehicle.bus
    compass, stats = bus.queue_reader("sensors/compass"), bus.queue_reader("system/plugin_stats")
    mag, status = bus.writer("sensors/mag"), bus.writer("vehicle/status")
    vehicle.wait_running("compass")
    now_us = MonotonicClock().now_us
    status.publish(VehicleStatus(t_us=now_us(), armed=1))
    mag.publish(Magnetometer(now_us(), 0.2, 0.0, 0.4))
    before = wait_for(lambda: _newest_steps(stats, b"compass"), 15, "the compass's counters")
    sent, got = 40, []
    for k in range(sent):  # 2 s of sentences at 20 Hz, the magnetometer speaking throughout
        # The status too, as a commander repeats it: a single publication may reach the
        # compass's reader only after the batches it decides have begun.
        status.publish(VehicleStatus(t_us=now_us(), armed=1))
        mag.publish(Magnetometer(now_us(), 0.2, 0.0, 0.4))
        pty.write(sentence(f"C{k:.1f}P0.0R0.0") + "\r\n")
        got += compass.take(0.05)  # taken as they come: the test's queue holds 32
    wait_for(lambda: got.extend(compass.take(0.2)) or len(got) >= sent, 20, "every sentence")
    headings = [round(math.degrees(c.heading_rad)) for c in got]
    assert headings == list(range(sent))  # none lost, none out of order
    stamps = [c.t_us for c in got]
    assert all(b > a for a, b in itertools.pairwise(stamps)), stamps
    # Its counters a second later cover the last batch: a wake-up a batch, not one a
    # sentence (40 over the 2 s; a busy machine only makes them fewer).
    after = wait_for(lambda: _newest_steps(stats, b"compass"), 15, "the compass's counters")
    after = wait_for(lambda: _newest_steps(stats, b"compass"), 15, "the compass's counters")
    assert after - before <= 2.0 / 0.2 + 8, (before, after)
    sensor = Os3000Compass()
    sensor.own_mag, sensor.ctx = False, SimpleNamespace(clock=SimpleNamespace(now_us=lambda: 0))
    sensor.other_mag = SimpleNamespace(get=lambda: Magnetometer(-600_000, 0.2, 0.0, 0.4))
    assert sensor.per_frame(VehicleStatus())  # silent for 0.6 s: the navigator's heading
    sensor.other_mag = SimpleNamespace(get=lambda: Magnetometer(-100_000, 0.2, 0.0, 0.4))
    assert not sensor.per_frame(VehicleStatus())
    sensor.own_mag = True  # the compass's own field: it is the magnetometer, read as it comes
    assert sensor.per_frame(VehicleStatus())
