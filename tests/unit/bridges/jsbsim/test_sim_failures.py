"""Failure injection on the simulator's emulated devices (bridges/jsbsim/failures.py)."""

from __future__ import annotations

from bridges.jsbsim.failures import DeviceFailures
from companion.messages import CommandResult
from companion.sensors.nmea_gps import NmeaGpsDecoder
from mavlink_dialect import companion as d

GGA = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n"
LATER = b"$GPGGA,123520,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*4F\r\n"


def test_healthy_devices_pass_through_unchanged():
    failures = DeviceFailures(seed=1)
    assert failures.filter("gps", GGA) == GGA
    assert failures.filter("imu", b"$VNIMU,...") == b"$VNIMU,..."


def test_gps_off_silences_only_the_gps_until_ok():
    failures = DeviceFailures(seed=1)
    result = failures.inject(d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_OFF, 0)
    assert result == CommandResult.ACCEPTED
    assert failures.filter("gps", GGA) is None
    assert failures.filter("compass", b"$C1.0P2.0R3.0T25.0*00") is not None
    failures.inject(d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_OK, 0)
    assert failures.filter("gps", LATER) == LATER


def test_stuck_repeats_the_last_healthy_output():
    failures = DeviceFailures(seed=1)
    failures.filter("gps", GGA)
    failures.inject(d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_STUCK, 1)
    assert failures.filter("gps", LATER) == GGA


def test_gyro_and_accel_fail_the_one_imu_line():
    for unit in (d.FAILURE_UNIT_SENSOR_GYRO, d.FAILURE_UNIT_SENSOR_ACCEL):
        failures = DeviceFailures(seed=1)
        failures.inject(unit, d.FAILURE_TYPE_OFF, 0)
        assert failures.filter("imu", b"$VNIMU,...") is None


def test_garbage_is_seeded_noise_the_driver_rejects():
    a, b = DeviceFailures(seed=7), DeviceFailures(seed=7)
    for f in (a, b):
        f.inject(d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_GARBAGE, 0)
    noise = a.filter("gps", GGA)
    assert noise is not None and len(noise) == len(GGA) and noise != GGA
    assert noise == b.filter("gps", GGA)  # same seed, same garbage
    assert NmeaGpsDecoder().decode(noise, 0) is None


def test_what_cannot_be_emulated_is_unsupported_and_changes_nothing():
    failures = DeviceFailures(seed=1)
    unsupported = [
        (d.FAILURE_UNIT_SENSOR_BARO, d.FAILURE_TYPE_OFF, 0),  # no barometer device
        (d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_SLOW, 0),  # type not emulated
        (d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_OFF, 2),  # there is one GPS
    ]
    for args in unsupported:
        assert failures.inject(*args) == CommandResult.UNSUPPORTED
    assert failures.filter("gps", GGA) == GGA
