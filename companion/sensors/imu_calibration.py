"""The IMU's calibration, applied where its samples are made.

Two corrections, with ArduPilot's names:
- ``INS_GYROFFS_X/Y/Z`` (rad/s, the IMU's own axes): what its gyros read while the
  aircraft stands still, taken off every sample. The gyro calibration measures it; the
  navigator still estimates what is left (its bias state, and the yaw-rate bias whenever
  the aircraft stands still), starting from zero.
- ``AHRS_TRIM_X/Y`` (rad): the roll and pitch the IMU reads on a level aircraft, its
  mounting's tilt. The tilt is rotated out of the accelerometer, gyro and magnetometer
  samples alike (as PX4 applies SENS_BOARD_X_OFF/Y_OFF to its raw sensors), so the
  navigator, the flight log and a replay of it all see the airframe's axes. The level
  calibration measures it.
Pure: numbers in, numbers out; plain floats, as this runs on every IMU sample.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from companion.messages import Imu, Magnetometer
from companion.params import ParamDecl

MAX_TRIM_RAD = math.radians(10.0)  # ArduPilot's AHRS_TRIM range: a mounting, not a bank
MAX_GYRO_OFFSET = 0.5  # rad/s; a MEMS gyro's turn-on bias is a few hundredths
GYRO_OFFSETS = ("INS_GYROFFS_X", "INS_GYROFFS_Y", "INS_GYROFFS_Z")
TRIMS = ("AHRS_TRIM_X", "AHRS_TRIM_Y")
Vec3 = tuple[float, float, float]
Matrix = tuple[Vec3, Vec3, Vec3]

IMU_CAL_PARAMS = (
    *(ParamDecl(name, 0.0, -MAX_GYRO_OFFSET, MAX_GYRO_OFFSET, "rad/s",
                f"Gyro offset, {axis} axis: taken off every sample (the gyro calibration "
                "measures it)") for name, axis in zip(GYRO_OFFSETS, "xyz", strict=True)),
    *(ParamDecl(name, 0.0, -MAX_TRIM_RAD, MAX_TRIM_RAD, "rad",
                f"{what} the IMU reads on a level aircraft: rotated out of its samples (the "
                "level calibration measures it)") for name, what in zip(TRIMS, ("Roll", "Pitch"),
                                                                          strict=True)),
)  # fmt: skip


def mounting(roll: float, pitch: float) -> Matrix:
    """The rotation from the IMU's axes to the airframe's for an IMU mounted rolled and
    pitched by these angles (rad): the direction cosines of that attitude."""
    sr, cr, sp, cp = math.sin(roll), math.cos(roll), math.sin(pitch), math.cos(pitch)
    return ((cp, sp * sr, sp * cr), (0.0, cr, -sr), (-sp, cp * sr, cp * cr))


def multiply(a: Matrix, b: Matrix) -> Matrix:
    """a · b."""
    return tuple(
        tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3)
    )  # type: ignore[return-value]


def transpose(m: Matrix) -> Matrix:
    """The inverse rotation."""
    return tuple(tuple(m[j][i] for j in range(3)) for i in range(3))  # type: ignore[return-value]


def roll_pitch(m: Matrix) -> tuple[float, float]:
    """The roll and pitch (rad) of a rotation from ``mounting`` (or a product of them)."""
    return math.atan2(m[2][1], m[2][2]), -math.asin(max(-1.0, min(1.0, m[2][0])))


def tilt(accel: Vec3) -> tuple[float, float]:
    """Roll and pitch (rad) of a still IMU from its mean specific force (body FRD)."""
    ax, ay, az = accel
    return math.atan2(-ay, -az), math.atan2(ax, math.hypot(ay, az))


def rotate(m: Matrix, x: float, y: float, z: float) -> Vec3:
    return (
        m[0][0] * x + m[0][1] * y + m[0][2] * z,
        m[1][0] * x + m[1][1] * y + m[1][2] * z,
        m[2][0] * x + m[2][1] * y + m[2][2] * z,
    )


@dataclass(frozen=True)
class ImuCalibration:
    """The corrections, resolved once from the parameters."""

    gyro_offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)
    trim: tuple[float, float] = (0.0, 0.0)

    @classmethod
    def from_params(cls, p: Mapping[str, float]) -> ImuCalibration:
        x, y, z = (p[name] for name in GYRO_OFFSETS)
        return cls((x, y, z), (p[TRIMS[0]], p[TRIMS[1]]))

    @property
    def rotation(self) -> Matrix | None:
        """IMU to airframe; None for a level mounting."""
        return mounting(*self.trim) if any(self.trim) else None

    def correct(self, imu: Imu, mag: Magnetometer | None, rotation: Matrix | None) -> None:
        """Correct the samples in place (``rotation``: this calibration's, computed once)."""
        ox, oy, oz = self.gyro_offsets
        gx, gy, gz = imu.gx_rad_s - ox, imu.gy_rad_s - oy, imu.gz_rad_s - oz
        if rotation is not None:
            gx, gy, gz = rotate(rotation, gx, gy, gz)
            ax, ay, az = rotate(rotation, imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2)
            imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2 = ax, ay, az
            if mag is not None:
                mx, my, mz = rotate(rotation, mag.mx_gauss, mag.my_gauss, mag.mz_gauss)
                mag.mx_gauss, mag.my_gauss, mag.mz_gauss = mx, my, mz
        imu.gx_rad_s, imu.gy_rad_s, imu.gz_rad_s = gx, gy, gz
