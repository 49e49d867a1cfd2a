"""Failure injection (MAV_CMD_INJECT_FAILURE) on the emulated devices.

As in PX4's simulators: a ground station or a MAVSDK script (``Failure.inject``) turns a
sensor off, freezes it, or makes it talk garbage, and back to normal with ``OK``. The
failure is applied where a real one would show: on the bytes the device puts on its wire,
so the vehicle's own drivers and navigator meet it exactly as they would in the air.

Units map onto the devices the bridge emulates: GPS → the NMEA receiver, MAG → the
OS-3000 compass, GYRO and ACCEL → the serial IMU (one device carries both, so either unit
fails the whole line), SYSTEM_BATTERY → the battery's power monitor. Instance 0 means every
instance; each device has one (instance 1).
"""

from __future__ import annotations

import logging

import numpy as np

from companion.messages import CommandResult
from mavlink_dialect import companion as d

log = logging.getLogger(__name__)

DEVICE_OF_UNIT = {
    d.FAILURE_UNIT_SENSOR_GPS: "gps",
    d.FAILURE_UNIT_SENSOR_MAG: "compass",
    d.FAILURE_UNIT_SENSOR_GYRO: "imu",
    d.FAILURE_UNIT_SENSOR_ACCEL: "imu",
    d.FAILURE_UNIT_SYSTEM_BATTERY: "battery",
}
SUPPORTED_TYPES = {
    d.FAILURE_TYPE_OK: "ok",
    d.FAILURE_TYPE_OFF: "off",
    d.FAILURE_TYPE_STUCK: "stuck",
    d.FAILURE_TYPE_GARBAGE: "garbage",
}


class DeviceFailures:
    """Which device is failed and how; filters what each device says."""

    def __init__(self, seed: int) -> None:
        self.active: dict[str, int] = {}  # device → FAILURE_TYPE (absent: healthy)
        self.last: dict[str, bytes] = {}  # the last healthy output, for STUCK
        self.rng = np.random.default_rng(seed + 0x5EED)

    def inject(self, unit: int, failure_type: int, instance: int) -> CommandResult:
        """Apply one MAV_CMD_INJECT_FAILURE; UNSUPPORTED for what cannot be emulated."""
        device = DEVICE_OF_UNIT.get(unit)
        if device is None or failure_type not in SUPPORTED_TYPES or instance not in (0, 1):
            return CommandResult.UNSUPPORTED
        if failure_type == d.FAILURE_TYPE_OK:
            self.active.pop(device, None)
        else:
            self.active[device] = failure_type
        log.info("failure injection: %s %s", device, SUPPORTED_TYPES[failure_type])
        return CommandResult.ACCEPTED

    def garbled(self) -> set[str]:
        """The devices whose bytes will not become samples (stuck repeats, garbage)."""
        return {dev for dev, f in self.active.items() if f != d.FAILURE_TYPE_OFF}

    def filter(self, device: str, data: bytes) -> bytes | None:
        """What the device puts on its wire instead of ``data`` (None: nothing)."""
        failure = self.active.get(device)
        if failure is None:
            self.last[device] = data
            return data
        if failure == d.FAILURE_TYPE_OFF:
            return None
        if failure == d.FAILURE_TYPE_STUCK:
            return self.last.get(device)
        return self.rng.integers(0, 256, len(data), dtype=np.uint8).tobytes()  # GARBAGE
