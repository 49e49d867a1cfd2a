"""What the emulated sensors get wrong: noise, bias drift, GPS error, the Earth's field.

All randomness comes from one seeded numpy Generator, so a seed gives the same errors.
``scale`` multiplies every noise and bias (0: perfect sensors).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from bridges.sensor_models.true_state import TrueState

EARTH_RADIUS_M = 6378137.0


@dataclass(frozen=True)
class NoiseModel:
    """1-σ figures of a VN-100-class IMU, an OS-3000 and a consumer GPS."""

    scale: float = 1.0
    accel_noise_m_s2: float = 0.03
    accel_bias_m_s2: float = 0.05  # turn-on bias
    accel_walk_m_s2_rt_s: float = 0.0005
    gyro_noise_rad_s: float = 0.003
    gyro_bias_rad_s: float = 0.003
    gyro_walk_rad_s_rt_s: float = 2e-5
    mag_noise_gauss: float = 0.002
    baro_noise_pa: float = 3.0  # about 0.25 m of height
    compass_heading_deg: float = 0.5
    compass_tilt_deg: float = 0.2
    gps_horizontal_m: float = 1.0  # slowly wandering error (Gauss-Markov), per axis
    gps_vertical_m: float = 2.0
    gps_correlation_s: float = 60.0
    gps_white_m: float = 0.3
    gps_velocity_m_s: float = 0.1
    gps_fix_quality: int = 1  # what the receiver's GGA says: 1 a GPS fix, 4 RTK fixed
    gps_hdop: float = 0.9
    # What a real airframe adds (all off here: the VN-100 on a quiet mount; ``installed``
    # gives an airframe's, calibrated or not). Magnetometer: a body-fixed offset (hard
    # iron, a poor calibration or a steel part), per-axis gains (soft iron) and the motor
    # current's field, in proportion to throttle; real logs show ±30-70° of heading error.
    mag_hard_iron_gauss: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mag_soft_iron: tuple[float, float, float] = (1.0, 1.0, 1.0)
    mag_throttle_gauss: tuple[float, float, float] = (0.0, 0.0, 0.0)  # at full throttle
    # Vibration (a propeller's, at vibration_hz): a point-sampled IMU at 10-25 Hz aliases it.
    # The amplitudes are at cruise power and above (vibration_throttle). A propeller's
    # imbalance force grows as the square of its speed, which runs from vibration_idle of
    # full speed with the throttle closed (c172p 770 of 2700 rpm, J3Cub 580 of 2300): idling
    # on the ground the airframe shakes at a tenth or so of the amplitude. Shaking at the
    # whole of it there gave 0.35 m/s² of accelerometer spread standing still, and no gyro
    # or level calibration could pass (issue 42.4).
    accel_vibration_m_s2: float = 0.0
    gyro_vibration_rad_s: float = 0.0
    vibration_hz: float = 87.0
    vibration_idle: float = 0.3
    vibration_throttle: float = 0.6

    def vibration_gain(self, throttle: float | None) -> float:
        """The fraction of the vibration amplitudes at this throttle (None: not known, all)."""
        if throttle is None:
            return 1.0
        idle = self.vibration_idle
        speed = idle + (1.0 - idle) * min(1.0, max(0.0, throttle))
        cruise = idle + (1.0 - idle) * self.vibration_throttle
        return min(1.0, (speed / cruise) ** 2)

    @classmethod
    def installed(cls, scale: float = 1.0, calibrated: bool = True) -> NoiseModel:
        """The same sensors as installed in a small airframe.

        Calibrated: what a good ground calibration and motor compensation (ArduPilot's
        COMPASS_MOT) leave: a hard-iron residue of 8 mG, 1 % soft iron, a fifth of the
        motor's field; about 2° of heading error that turns with the heading. Uncalibrated:
        a tenth of Melbourne's 0.21 G horizontal field as hard iron (up to 7° that turns with
        the heading), 2-4 % soft iron, the motor's whole field (5° more at full throttle and
        a field strength that swings with it). Both: propeller vibration the IMU's own
        filter does not take out entirely.
        """
        if calibrated:
            iron, gains, motor = (0.006, -0.005, 0.004), (1.01, 0.99, 1.01), (0.0025, 0.002, -0.004)
        else:
            iron, gains, motor = (0.02, -0.015, 0.01), (1.04, 0.97, 1.02), (0.012, 0.01, -0.02)
        return cls(
            scale=scale,
            mag_hard_iron_gauss=iron,
            mag_soft_iron=gains,
            mag_throttle_gauss=motor,
            accel_vibration_m_s2=0.5,
            gyro_vibration_rad_s=0.01,
        )

    def with_rtk(self) -> NoiseModel:
        """The same sensors with an RTK receiver holding a fixed solution (ZED-F9P class:
        1 cm + 1 ppm CEP with its base a few kilometres away), its GGA saying so."""
        return dataclasses.replace(
            self,
            gps_horizontal_m=0.01,
            gps_vertical_m=0.02,
            gps_white_m=0.005,
            gps_velocity_m_s=0.05,
            gps_fix_quality=4,
            gps_hdop=0.6,
        )

    def with_rtk_float(self) -> NoiseModel:
        """The same RTK receiver before it has fixed its carrier-phase ambiguities: a float
        solution, decimetres off, its GGA saying so (quality 5)."""
        return dataclasses.replace(
            self.with_rtk(),
            gps_horizontal_m=0.15,
            gps_vertical_m=0.3,
            gps_white_m=0.03,
            gps_fix_quality=5,
            gps_hdop=0.7,
        )


@dataclass(frozen=True)
class MagneticField:
    """A uniform field (near enough over a flight); defaults: Melbourne, 2026."""

    declination_deg: float = 11.7
    inclination_deg: float = -68.9
    intensity_gauss: float = 0.583

    def ned(self) -> np.ndarray:
        """The field vector in NED, gauss."""
        d, i = math.radians(self.declination_deg), math.radians(self.inclination_deg)
        return self.intensity_gauss * np.array(
            [math.cos(i) * math.cos(d), math.cos(i) * math.sin(d), math.sin(i)]
        )


def body_from_ned(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rotation taking NED vectors into body FRD (ZYX Euler angles)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cp * cy, cp * sy, -sp],
            [sr * sp * cy - cr * sy, sr * sp * sy + cr * cy, sr * cp],
            [cr * sp * cy + sr * sy, cr * sp * sy - sr * cy, cr * cp],
        ]
    )


def levelled_heading_deg(mag_body: np.ndarray, roll: float, pitch: float) -> float:
    """The heading a compass finds from its field, levelled by its own roll and pitch.

    Rotating the body field back through roll and pitch leaves it in the heading frame
    (x forward and level, y right), where magnetic north lies at minus the heading.
    """
    level = body_from_ned(roll, pitch, 0.0).T @ mag_body
    return math.degrees(math.atan2(-level[1], level[0]))


@dataclass
class ImuSample:
    """What the IMU measures: specific force, rate and field, body FRD."""

    accel: np.ndarray
    gyro: np.ndarray
    mag: np.ndarray
    temp_c: float
    pressure_kpa: float


# What a receiver reports: lat, lon (degrees), altitude MSL (m), NED velocity (m/s).
GpsMeasurement = tuple[float, float, float, np.ndarray]


class SensorErrors:
    """The sensors' error processes, advanced in simulation time."""

    def __init__(self, model: NoiseModel, field: MagneticField, seed: int) -> None:
        self.m, self.field = model, field
        self.rng = np.random.default_rng(seed)
        k = model.scale
        self.accel_bias = self.rng.normal(0.0, model.accel_bias_m_s2 * k, 3)
        self.gyro_bias = self.rng.normal(0.0, model.gyro_bias_rad_s * k, 3)
        self.gps_error = self.rng.normal(0.0, 1.0, 3) * self._gps_sigma()
        self.field_ned = field.ned()
        self.vibration_phase = np.array([0.0, 2.1, 4.2])  # the axes shake out of step

    def _gps_sigma(self) -> np.ndarray:
        k = self.m.scale
        return (
            np.array([self.m.gps_horizontal_m, self.m.gps_horizontal_m, self.m.gps_vertical_m]) * k
        )

    def imu(
        self, s: TrueState, dt: float, pressure_kpa: float, throttle: float | None = None
    ) -> ImuSample:
        """One IMU sample; the biases walk by ``dt`` seconds first. ``throttle`` (0-1) sets
        the propeller's vibration and the motor's field (None: full vibration, no field)."""
        m = self.m
        root = math.sqrt(max(dt, 0.0))
        # One draw for all sixteen: the IMU runs at 100 Hz and more.
        z = self.rng.standard_normal(16) * m.scale
        self.accel_bias += z[0:3] * (m.accel_walk_m_s2_rt_s * root)
        self.gyro_bias += z[3:6] * (m.gyro_walk_rad_s_rt_s * root)
        accel = np.array(s.f_body) + self.accel_bias + z[6:9] * m.accel_noise_m_s2
        gyro = np.array((s.p, s.q, s.r)) + self.gyro_bias + z[9:12] * m.gyro_noise_rad_s
        if m.accel_vibration_m_s2 or m.gyro_vibration_rad_s:
            shake = np.sin(math.tau * m.vibration_hz * s.t_s + self.vibration_phase)
            shake *= m.scale * m.vibration_gain(throttle)
            accel += shake * m.accel_vibration_m_s2
            gyro += shake * m.gyro_vibration_rad_s
        mag = self.airframe_field(s, throttle or 0.0) + z[12:15] * m.mag_noise_gauss
        pressure_kpa += z[15] * m.baro_noise_pa / 1000.0
        return ImuSample(accel, gyro, mag, 25.0, pressure_kpa)

    def airframe_field(self, s: TrueState, throttle: float) -> np.ndarray:
        """The field a magnetometer in the airframe sees, body FRD: the Earth's through
        soft and hard iron, plus the motor's; the defects scale with ``scale`` as noise."""
        m, k = self.m, self.m.scale
        mag = body_from_ned(s.roll, s.pitch, s.yaw) @ self.field_ned
        gains = 1.0 + (np.array(m.mag_soft_iron) - 1.0) * k
        offset = np.array(m.mag_hard_iron_gauss) + np.array(m.mag_throttle_gauss) * throttle
        return mag * gains + offset * k

    def compass(self, s: TrueState, throttle: float = 0.0) -> tuple[float, float, float]:
        """(magnetic heading [0, 360), pitch, roll) in degrees, as an OS-3000 reports them.

        Like the real part, it levels itself with its accelerometer: in a turn or while
        accelerating the specific force is not vertical, so pitch and roll are wrong
        (a coordinated turn reads wings level) and the tilt-compensated heading with them.
        """
        k, rng = self.m.scale, self.rng
        fx, fy, fz = s.f_body
        roll = math.atan2(-fy, -fz) + math.radians(rng.normal(0.0, self.m.compass_tilt_deg * k))
        pitch = math.atan2(fx, math.hypot(fy, fz))
        pitch += math.radians(rng.normal(0.0, self.m.compass_tilt_deg * k))
        # It sits in the same airframe as the IMU: the same iron and motor disturb it.
        heading = levelled_heading_deg(self.airframe_field(s, throttle), roll, pitch)
        heading += rng.normal(0.0, self.m.compass_heading_deg * k)
        return heading % 360.0, math.degrees(pitch), math.degrees(roll)

    def gps(self, s: TrueState, dt: float) -> GpsMeasurement:
        """(lat, lon, alt MSL, NED velocity) with the receiver's error; error evolves by dt."""
        m, rng = self.m, self.rng
        a = math.exp(-dt / m.gps_correlation_s) if m.gps_correlation_s > 0 else 0.0
        self.gps_error = (
            a * self.gps_error + math.sqrt(1 - a * a) * rng.normal(0.0, 1.0, 3) * self._gps_sigma()
        )
        err = self.gps_error + rng.normal(0.0, m.gps_white_m * m.scale, 3)
        lat = s.lat_deg + math.degrees(err[0] / EARTH_RADIUS_M)
        lon = s.lon_deg + math.degrees(
            err[1] / (EARTH_RADIUS_M * math.cos(math.radians(s.lat_deg)))
        )
        vel = np.array([s.vn, s.ve, s.vd]) + rng.normal(0.0, m.gps_velocity_m_s * m.scale, 3)
        return lat, lon, s.alt_msl_m - err[2], vel
