"""The serial sensor plug-ins on real ptys under hostile streams: nothing restarts, the bad
is counted, the good still gets through, and nothing infinite reaches the bus."""

from __future__ import annotations

import math
import time

from companion.messages import PluginState
from tests.support.configs import plugin, vehicle_config
from tests.support.hostile_sentences import compass_valid, hostile_stream, imu_valid, nmea_valid
from tests.support.pty import Pty
from tests.support.vehicle import wait_for

SECONDS = 6.0
DEVICES = {  # plug-in name: (plug-in kind, valid sentence, bus channels it publishes)
    "gps": ("sensors.nmea_gps", nmea_valid, ("sensors/gps",)),
    "compass": ("sensors.os3000", compass_valid, ("sensors/compass", "sensors/mag")),
    "imu": ("sensors.serial_imu", imu_valid, ("sensors/imu", "sensors/mag")),
}


def sensors_vehicle(ptys: dict[str, Pty]) -> str:
    sensors = (plugin(name, kind, device=ptys[name].link) for name, (kind, _, _) in DEVICES.items())
    return vehicle_config("devices", *sensors)


def no_infinities(sample) -> bool:
    values = [v for v in sample.as_dict().values() if isinstance(v, float)]
    return not any(math.isinf(v) for v in values)


def test_hostile_device_streams_are_counted_and_survived(vehicle_factory, tmp_path):
    ptys = {name: Pty(tmp_path / f"tty_{name}") for name in DEVICES}
    vehicle = vehicle_factory(sensors_vehicle(ptys))
    for name in DEVICES:
        vehicle.wait_running(name)
    streams = {name: hostile_stream(valid, seed=i) for i, (name, (_, valid, _)) in
               enumerate(DEVICES.items())}  # fmt: skip
    readers = {ch: vehicle.bus.queue_reader(ch) for _, _, chans in DEVICES.values() for ch in chans}
    published = {ch: [] for ch in readers}
    valid_sent = dict.fromkeys(DEVICES, 0)
    end = time.monotonic() + SECONDS
    while time.monotonic() < end:
        for name, stream in streams.items():
            text, valid = stream()
            ptys[name].write(text)
            valid_sent[name] += valid
        for channel, reader in readers.items():
            published[channel] += reader.drain()
        time.sleep(0.002)

    def counted() -> bool:
        rows = {n: vehicle.row(n) for n in DEVICES}
        return all(r is not None and r.frames_ok > 0 and r.frames_bad > 0 for r in rows.values())

    wait_for(counted, 10, "good and bad frames counted on every device")
    for name in DEVICES:
        row = vehicle.row(name)
        assert row.restarts == 0 and row.state == PluginState.RUNNING, name
    for channel, samples in published.items():
        assert samples, f"nothing on {channel}: the valid sentences must still get through"
        assert all(no_infinities(s) for s in samples), channel
