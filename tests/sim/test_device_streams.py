"""The bridge's emulated devices speak exactly what the companion's own drivers parse."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bridges.jsbsim.device_streams import (
    DeviceRates,
    EmulatedDevices,
    Outage,
    nmea_epoch,
    os3000_sentence,
)
from bridges.sensor_models.sensor_errors import (
    MagneticField,
    NoiseModel,
    SensorErrors,
    body_from_ned,
)
from bridges.sensor_models.true_state import TrueState
from companion.messages import GpsFixType
from companion.sensors.line_framer import LineFramer
from companion.sensors.nmea_gps import NmeaGpsDecoder
from companion.sensors.os3000 import Os3000Decoder
from companion.sensors.vectornav import VectorNavDecoder

FIELD = MagneticField()


def state(t_s: float, yaw_deg: float = 30.0) -> TrueState:
    return TrueState(
        t_s=t_s, lat_deg=-37.9105, lon_deg=145.134, alt_msl_m=380.0, alt_agl_m=300.0,
        roll=math.radians(10.0), pitch=math.radians(-3.0), yaw=math.radians(yaw_deg),
        vn=40.0, ve=25.0, vd=-1.0, p=0.01, q=-0.02, r=0.03, f_body=(0.5, 0.2, -9.7),
        airspeed_m_s=47.0,
    )  # fmt: skip


def perfect_devices(outages=()) -> EmulatedDevices:
    errors = SensorErrors(NoiseModel(scale=0.0), FIELD, seed=3)
    rates = DeviceRates(gps_latency_s=0.0, gps_latency_jitter_s=0.0)
    return EmulatedDevices(errors, rates, list(outages))


def lines(devices: EmulatedDevices, t_s: float, kind: str) -> list[bytes]:
    framer = LineFramer()
    out = []
    for name, _, data in devices.due(state(t_s), 95.0):
        if name == kind:
            out += framer.feed(data)
    return out


def test_imu_lines_decode_to_the_true_specific_force_rates_and_field():
    devices = perfect_devices()
    (line,) = lines(devices, 0.0, "imu")
    reading = VectorNavDecoder().decode(line, 7)
    assert reading is not None
    imu = reading.imu
    assert (imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2) == pytest.approx((0.5, 0.2, -9.7), abs=1e-4)
    assert (imu.gx_rad_s, imu.gy_rad_s, imu.gz_rad_s) == pytest.approx((0.01, -0.02, 0.03))
    mag = np.array([reading.mag.mx_gauss, reading.mag.my_gauss, reading.mag.mz_gauss])
    assert np.linalg.norm(mag) == pytest.approx(FIELD.intensity_gauss, abs=2e-4)
    assert reading.pressure_pa == pytest.approx(95000.0)


def test_compass_reports_magnetic_heading_to_a_tenth_of_a_degree():
    still = state(0.0)
    gravity = body_from_ned(still.roll, still.pitch, still.yaw) @ np.array([0.0, 0.0, -9.8])
    still.f_body = tuple(gravity)  # held still: the compass levels itself correctly
    errors = SensorErrors(NoiseModel(scale=0.0), FIELD, seed=3)
    reading = Os3000Decoder().decode(
        LineFramer().feed(os3000_sentence(*errors.compass(still), 25.0))[0], 7
    )
    assert reading is not None
    magnetic = (30.0 - FIELD.declination_deg) % 360
    assert math.degrees(reading.compass.heading_rad) == pytest.approx(magnetic, abs=0.051)
    assert math.degrees(reading.compass.roll_rad) == pytest.approx(10.0, abs=0.051)
    assert math.degrees(reading.compass.pitch_rad) == pytest.approx(-3.0, abs=0.051)


def test_in_a_coordinated_turn_the_compass_reads_wings_level_and_a_wrong_heading():
    turning = state(0.0)  # banked 10°, but the specific force stays in the plane of symmetry
    turning.f_body = (0.0, 0.0, -9.95)
    errors = SensorErrors(NoiseModel(scale=0.0), FIELD, seed=3)
    heading, _, roll = errors.compass(turning)
    assert roll == pytest.approx(0.0, abs=1e-9)
    error = math.remainder(heading - (30.0 - FIELD.declination_deg), 360.0)
    assert abs(error) > 5.0  # the thesis's trouble: a tilt error is a bigger heading error


def test_gps_epochs_decode_to_the_true_position_and_velocity():
    devices, decoder = perfect_devices(), NmeaGpsDecoder()
    fixes = []
    for k in range(3):  # the decoder learns the receiver's epoch order from the first
        for line in lines(devices, 0.2 * k, "gps"):
            fixes.append(decoder.decode(line, k))
    fix = [f for f in fixes if f is not None][-1]
    assert fix.fix_type == GpsFixType.FIX_3D
    assert (fix.lat_deg, fix.lon_deg) == pytest.approx((-37.9105, 145.134), abs=1e-7)
    assert fix.alt_msl_m == pytest.approx(380.0, abs=0.05)
    assert (fix.vn_m_s, fix.ve_m_s) == pytest.approx((40.0, 25.0), abs=0.02)
    assert decoder.counters.bad_checksum == decoder.counters.garbage == 0


def test_an_outage_window_sends_epochs_without_a_fix():
    decoder = NmeaGpsDecoder()
    for t in (0.0, 0.2, 0.4):
        for line in LineFramer().feed(nmea_epoch(t, -37.9, 145.1, 80.0, 1.0, 0.0, fix=True)):
            decoder.decode(line, 1)
    devices = perfect_devices([Outage(1.0, 5.0)])
    devices.next_s["gps"] = 1.2
    out = [f for line in lines(devices, 1.2, "gps") if (f := decoder.decode(line, 2))]
    assert [f.fix_type for f in out] == [GpsFixType.NO_FIX]
    assert math.isnan(out[0].lat_deg)
    assert decoder.counters.bad_checksum == 0


def test_the_same_seed_gives_the_same_errors():
    def imu_text(seed: int) -> bytes:
        errors = SensorErrors(NoiseModel(), FIELD, seed)
        devices = EmulatedDevices(errors, DeviceRates(), [])
        return b"".join(d for _, _, d in devices.due(state(0.0), 95.0))

    assert imu_text(5) == imu_text(5)
    assert imu_text(5) != imu_text(6)
