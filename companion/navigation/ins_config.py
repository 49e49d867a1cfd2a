"""The INS's settings: noise densities, initial uncertainties, gates."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class InsEkfConfig:
    """Noise densities, initial uncertainties, gates. Defaults: a MEMS IMU (VN-100 class).

    ``declination_deg`` None: the World Magnetic Model's at the first fix (and compass
    headings are then taken as magnetic). ``gps_delay_s`` None: measured in flight.
    """

    # Noise densities a little above a VN-100's datasheet (0.14 mg/√Hz, 0.0035 °/s/√Hz):
    # much larger values let a heading update drag the tilt about during GPS outages. The
    # filter raises them when the IMU's own samples are noisier (vibration, point samples).
    accel_noise: float = 0.01  # m/s² / √Hz (velocity random walk)
    gyro_noise: float = 5e-4  # rad/s / √Hz (angle random walk)
    accel_bias_walk: float = 1e-3  # m/s² / √s
    gyro_bias_walk: float = 5e-5  # rad/s / √s
    accel_bias_std: float = 0.1  # initial 1-σ
    gyro_bias_std: float = math.radians(0.5)
    gps_pos_std: float = 3.0  # when the fix carries no accuracy
    # The least position noise a fix is fused with, whatever it claims: an RTK fix's
    # centimetres are finer than the IMU's propagation between fixes and the measured
    # lag's error (0.02 s at 30 m/s is 0.6 m), which would then read as the GPS's fault.
    gps_pos_min_std: float = 0.3
    gps_vel_std: float = 0.3
    baro_std: float = 0.5  # m, barometric height over seconds
    baro_interval_s: float = 0.1
    baro_timeout_s: float = 1.0  # barometer silent this long: GPS height again
    baro_offset_tau_s: float = 300.0  # how slowly GPS pulls the baro datum (standing only)
    gps_vert_with_baro_std: float = 10.0  # GPS height beside the barometer's, weakly
    compass_std: float = math.radians(2.0)
    mag_heading_std: float = math.radians(4.0)
    mag_window_s: float = 5.0  # the magnetometer's consistency is judged over this
    mag_max_nis: float = 4.0  # mean normalised innovation² above which it is not fused
    declination_deg: float | None = None
    field_year: float = 2020.0  # decimal year for the World Magnetic Model
    gps_delay_s: float | None = None
    gps_lag_window_s: float = 60.0
    gps_timeout_s: float = 2.0
    heading_timeout_s: float = 1.0  # magnetometer silent this long: use the compass
    reset_after: int = 10
    heading_interval_s: float = 0.2  # magnetometer heading updates at most this often
    covariance_interval_s: float = 0.04
    align_window_s: float = 0.5
    settle_s: float = 5.0  # GPS is not gated for this long after the alignment
    still_window_s: float = 1.0  # standing still this long measures the gyro biases
    noise_window_s: float = 10.0  # the IMU's sample noise is measured over this

    def fix_pos_std(self, eph_m: float) -> float:
        """The horizontal position noise a fix claiming ``eph_m`` is fused with."""
        claimed = eph_m if math.isfinite(eph_m) and eph_m > 0 else self.gps_pos_std
        return max(claimed, self.gps_pos_min_std)
