"""The simulator's sensors as installed in an airframe (``companion sim --mount``): the iron
and the motor's field turn the magnetometer and the compass, a calibration leaves a little
of it; the GPS's latency varies epoch to epoch; an airborne start can begin in a bank."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bridges.jsbsim.device_streams import DeviceRates, EmulatedDevices
from bridges.jsbsim.fdm import Flight, Home
from bridges.jsbsim.options import BridgeOptions
from bridges.sensor_models.sensor_errors import (
    MagneticField,
    NoiseModel,
    SensorErrors,
    body_from_ned,
)
from bridges.sensor_models.true_state import TrueState
from companion.sensors.line_framer import LineFramer
from companion.sensors.os3000 import Os3000Decoder
from companion.sensors.vectornav import VectorNavDecoder

FIELD = MagneticField()


def level(yaw_deg: float, t_s: float = 0.0) -> TrueState:
    return TrueState(
        t_s=t_s, lat_deg=-37.9105, lon_deg=145.134, alt_msl_m=380.0, alt_agl_m=300.0,
        roll=0.0, pitch=0.0, yaw=math.radians(yaw_deg), vn=40.0, ve=0.0, vd=0.0,
        p=0.0, q=0.0, r=0.0, f_body=(0.0, 0.0, -9.80665), airspeed_m_s=40.0,
    )  # fmt: skip


def installed(scale: float = 1.0, calibrated: bool = False) -> SensorErrors:
    return SensorErrors(NoiseModel.installed(scale, calibrated), FIELD, seed=3)


def compass_heading(errors: SensorErrors, yaw_deg: float, throttle: float) -> float:
    devices = EmulatedDevices(errors, DeviceRates(), [])
    sentence = next(d for k, _, d in devices.due(level(yaw_deg), 95.0, throttle) if k == "compass")
    reading = Os3000Decoder().decode(LineFramer().feed(sentence)[0], 0)
    return math.degrees(reading.compass.heading_rad)


def heading_error(measured: float, true_deg: float) -> float:
    """Measured magnetic heading against the true one turned magnetic, -180..180."""
    return (measured - (true_deg - FIELD.declination_deg) + 180.0) % 360.0 - 180.0


def test_the_installed_compass_errs_by_heading_as_a_calibrated_airframe_does():
    errors = [
        heading_error(compass_heading(installed(), yaw, 0.0), yaw) for yaw in range(0, 360, 30)
    ]
    # Hard iron: an error that turns with the heading, a few degrees, never tens of them.
    assert 3.0 < max(abs(e) for e in errors) < 12.0
    assert max(errors) - min(errors) > 5.0


def test_a_calibration_leaves_a_few_degrees_that_still_turn_with_the_heading():
    def worst(errors: SensorErrors) -> float:
        return max(
            abs(heading_error(compass_heading(errors, yaw, 1.0), yaw)) for yaw in range(0, 360, 30)
        )

    assert 1.0 < worst(installed(calibrated=True)) < 4.0 < worst(installed())


def test_the_motor_turns_the_heading_and_swings_the_field_with_throttle():
    idle = compass_heading(installed(), 90.0, 0.0)
    full = compass_heading(installed(), 90.0, 1.0)
    assert 2.0 < abs(heading_error(full, 90.0) - heading_error(idle, 90.0)) < 10.0
    errors = installed()
    strengths = [
        float(np.linalg.norm(errors.airframe_field(level(90.0), throttle)))
        for throttle in (0.0, 1.0)
    ]
    assert abs(strengths[1] - strengths[0]) / strengths[0] > 0.02


def test_a_quiet_mount_and_a_zero_noise_scale_leave_the_field_undisturbed():
    state = level(45.0)
    earth = body_from_ned(state.roll, state.pitch, state.yaw) @ FIELD.ned()
    for errors, tolerance in ((SensorErrors(NoiseModel(), FIELD, 3), 0.01), (installed(0.0), 1e-4)):
        devices = EmulatedDevices(errors, DeviceRates(), [])
        sentence = next(d for k, _, d in devices.due(state, 95.0, 1.0) if k == "imu")
        mag = VectorNavDecoder().decode(LineFramer().feed(sentence)[0], 0).mag
        measured = (mag.mx_gauss, mag.my_gauss, mag.mz_gauss)
        assert measured == pytest.approx(tuple(earth), abs=tolerance)


def test_the_gps_latency_varies_within_its_jitter_and_the_seed_repeats_it():
    def release_delays(seed: int) -> list[float]:
        devices = EmulatedDevices(installed(), DeviceRates(), [], seed)
        delays = []
        for k in range(0, 3000):
            t = k / 100.0
            delays += [r - t for name, r, _ in devices.due(level(0.0, t), 95.0) if name == "gps"]
        return delays

    delays = release_delays(5)
    rates = DeviceRates()
    assert len(delays) == 150  # 5 Hz for 30 s
    assert min(delays) >= rates.gps_latency_s - rates.gps_latency_jitter_s
    assert max(delays) <= rates.gps_latency_s + rates.gps_latency_jitter_s
    assert np.std(delays) > rates.gps_latency_jitter_s / 3  # uniform: jitter / sqrt(3)
    assert release_delays(5) == delays and release_delays(6) != delays
    # Never so late that a fix would overtake the one before it.
    assert all(b > a for a, b in zip(delays, [d + 0.2 for d in delays[1:]], strict=False))


def test_a_jitter_larger_than_the_latency_is_refused():
    with pytest.raises(ValueError, match="jitter"):
        EmulatedDevices(installed(), DeviceRates(gps_latency_s=0.05, gps_latency_jitter_s=0.1), [])


def test_an_airborne_start_in_a_bank_begins_banked_at_speed_and_height():
    flight = Flight("c172p", 100.0, Home(), airborne_agl_m=300.0, speed_m_s=55.0, bank_deg=45.0)
    start = flight.fdm
    assert start["attitude/phi-deg"] == pytest.approx(45.0, abs=0.5)
    assert start["position/h-agl-ft"] * 0.3048 == pytest.approx(300.0, abs=1.0)
    assert start["velocities/vc-kts"] * 0.514444 == pytest.approx(55.0, abs=1.0)
    with pytest.raises(ValueError, match="bank"):
        BridgeOptions(airborne=True, airborne_bank_deg=95.0)
    with pytest.raises(ValueError, match="mount"):
        BridgeOptions(mount="bolted")
