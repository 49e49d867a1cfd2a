"""Strapdown INS with a 15-state error-state extended Kalman filter.

Nominal state: position and velocity in a local NED frame (``LocalFrame``, about the first
fix), attitude as a body→NED quaternion, accelerometer and gyro biases. Error state
δx = [δp, δv, δθ (body frame), δb_a, δb_g]. The IMU drives the prediction with the true
time between samples and WGS-84 normal gravity; GPS position and velocity and a heading
(compass, or the tilt-compensated magnetometer) correct it. Every update passes an
innovation gate (normalised innovation squared against the χ² 99.99 % point): outliers
are rejected and counted, and after ``reset_after`` GPS rejections in a row the position
and velocity are reset to GPS rather than trusted forever. Without GPS the INS dead
reckons, its uncertainty growing. GPS fixes that lag the IMU are compared with the state
of their own time (the lag is measured in flight unless configured; ``ins_gps``). The
magnetometer's heading is checked against the World Magnetic Model and against what the
INS has learnt from GPS, and left out while it disagrees (``ins_mag``). The process noise
follows the IMU's own sample-to-sample noise when that is larger than the configured
densities (vibration aliased into point samples). Earth rotation and transport rate are not
modelled (below a consumer IMU's noise).

Feed samples in time order (``on_imu``, ``on_gps``, ``on_compass``, ``on_mag``);
``state()`` is the solution at the last IMU sample.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer
from companion.navigation import rotations as rot
from companion.navigation.baro_datum import BaroDatum
from companion.navigation.earth_field import EarthField, configured_field
from companion.navigation.ins_align import Aligner, Alignment
from companion.navigation.ins_config import InsEkfConfig
from companion.navigation.ins_core import TH, InsCore
from companion.navigation.ins_gps import GpsLag
from companion.navigation.ins_mag import MagHeading, MagMonitor, mag_heading, yaw_jacobian
from companion.navigation.ins_still import StillDetector
from companion.navigation.ins_warm import WarmState, waits_for_alignment, warm_start
from companion.navigation.local_frame import LocalFrame, normal_gravity
from companion.navigation.yaw_gsf import YawGsf

MAX_IMU_GAP_S = 0.5
COMPASS_TILT_TO_HEADING = 3.0
LAG_MAX_WANDER = 0.5
LOST_TILT_STD, LOST_YAW_STD = math.radians(5.0), math.radians(30.0)
GSF_MIN_VEL_STD = 0.5  # m/s: the bank ignores the GPS lag, which this allows for
GSF_STEP_S = 0.04  # the yaw estimator bank integrates the IMU in steps of this
# The bank's heading is believed over the INS's only when the bank is this sure, and the two
# disagree by more than a heading error anyone would accept, for longer than a manoeuvre.
GSF_TRUST_STD = math.radians(10.0)
GSF_DISAGREE_RAD, GSF_DISAGREE_S = math.radians(30.0), 2.0
_I15 = np.eye(15)
_YAW_ONLY = np.array([True] * 6 + [False, False, True] + [False] * 3 + [True] * 3)
__all__ = ["InsEkf", "InsEkfConfig"]


class InsEkf(InsCore):
    """The navigator; see the module doc."""

    def __init__(self, config: InsEkfConfig | None = None) -> None:
        super().__init__(config)
        c = self.cfg
        self.aligner = Aligner(c.align_window_s, 9.80665)
        self.field: EarthField | None = None
        self.last_compass: Compass | None = None
        self.last_mag: np.ndarray | None = None
        self.last_mag_us: int | None = None
        self.pending_fix: GpsFix | None = None
        self.gps_reject_run = self.baro_reject_run = self.resets = 0
        self.aligned_us = self.next_heading_us = 0
        self.baro = BaroDatum(c.baro_interval_s, c.baro_timeout_s, c.baro_offset_tau_s)
        self.lag = GpsLag(c.gps_lag_window_s, c.gps_delay_s or 0.0)
        self.mag_monitor = MagMonitor(c.mag_window_s, c.mag_max_nis)
        self.gsf, self.gsf_dt = YawGsf(), 0.0
        self.gsf_sums = [0.0] * 6  # specific force and rate, times dt
        self.gsf_disagree_us: int | None = None
        self.still = StillDetector(c.still_window_s)
        self.ground_speed, self.still_updates = math.nan, 0
        self.yaw_resets = 0  # headings taken from the bank
        self.warm: WarmState | None = None  # the last solution of a killed process

    # -- inputs ---------------------------------------------------------------------
    def on_imu(self, imu: Imu) -> None:
        """Propagate to the sample's time (or collect it for the alignment)."""
        values = (imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2, imu.gx_rad_s, imu.gy_rad_s, imu.gz_rad_s)
        if not math.isfinite(sum(values)):
            return
        dt = (imu.t_us - self.t_us) / 1e6 if self.t_us is not None else 0.0
        if dt > MAX_IMU_GAP_S:
            self.noise.last = None  # no difference across a hole
        elif dt > 0.0:
            self.noise.add(values, dt)
        if not self.aligned:
            self._collect(imu.t_us, np.array(values[:3]), np.array(values[3:]))
            return
        self.t_us = imu.t_us
        if dt <= 0.0:
            return
        if dt > MAX_IMU_GAP_S:  # a hole in the data: time passes, nothing is integrated
            self._flush_covariance()
            self.cov_dt = dt
            self._flush_covariance()
            return
        ba, bg = self.ba, self.bg
        f = (values[0] - ba[0], values[1] - ba[1], values[2] - ba[2])
        w = (values[3] - bg[0], values[4] - bg[1], values[5] - bg[2])
        self._integrate(dt, f, w)
        self._feed_gsf(dt, f, w)
        speed = self.ground_speed if self._fresh_fix(imu.t_us) else math.nan
        found = self.still.add(imu.t_us, values[:3], values[3:], speed)
        if found is not None:
            self._still_update(*found)

    def _fresh_fix(self, t_us: int) -> bool:
        return self.last_fix_us is not None and (t_us - self.last_fix_us) / 1e6 < 1.0

    def _still_update(self, gyro_mean: np.ndarray, variance: float) -> None:
        """Standing still: the gyros' mean is their bias (``ins_still``)."""
        # The yaw-rate bias only: roll and pitch rate biases are seen in flight through the
        # tilt (gravity, GPS), and with the propellers turning they shift from the ground's
        # (vibration, g-sensitivity); the yaw-rate bias has nothing but a magnetometer in
        # flight, and a stationary window measures it to a few thousandths of a degree/s.
        self.baro.standing(self.t_us)  # on the ground: GPS may set the barometer's datum
        ok = self._update(gyro_mean[2:] - self.bg[2:], [14], np.array([[variance]]))
        if ok:
            self.still_updates += 1

    def _feed_gsf(self, dt: float, f: tuple[float, ...], w: tuple[float, ...]) -> None:
        """The yaw estimator bank gets the IMU averaged over a few samples (at 200-400 Hz
        every sample would cost more than the bank's heading is worth)."""
        self.gsf_dt += dt
        s = self.gsf_sums
        s[0], s[1], s[2] = s[0] + f[0] * dt, s[1] + f[1] * dt, s[2] + f[2] * dt
        s[3], s[4], s[5] = s[3] + w[0] * dt, s[4] + w[1] * dt, s[5] + w[2] * dt
        if self.gsf_dt < GSF_STEP_S:
            return
        roll, pitch, _ = rot.quaternion_to_euler(self.q)
        dt_sum = self.gsf_dt
        mean = [x / dt_sum for x in s]  # floats: the bank's per-model sums stay off numpy scalars
        self.gsf.predict(dt_sum, mean[:3], mean[3:], roll, pitch)
        self.gsf_dt = 0.0
        self.gsf_sums = [0.0] * 6

    def on_gps(self, fix: GpsFix) -> None:
        """Position and velocity update (or the first fix, which anchors the frame)."""
        if fix.fix_type < 2 or not (math.isfinite(fix.lat_deg) and math.isfinite(fix.lon_deg)):
            return
        self.last_fix_us = fix.t_us if self.last_fix_us is None else max(self.last_fix_us, fix.t_us)
        self.ground_speed = math.hypot(fix.vn_m_s, fix.ve_m_s)
        if self.frame is None:
            alt = fix.alt_msl_m if math.isfinite(fix.alt_msl_m) else 0.0
            self.frame = LocalFrame(fix.lat_deg, fix.lon_deg, alt)
            self.g[2] = self.aligner.g = normal_gravity(fix.lat_deg, alt)
            self.field = configured_field(
                fix.lat_deg, fix.lon_deg, alt, self.cfg.field_year, self.cfg.declination_deg
            )
        if not self.aligned:
            self.pending_fix = fix
            return
        self.gsf.update(fix.vn_m_s, fix.ve_m_s, max(self.cfg.gps_vel_std, GSF_MIN_VEL_STD))
        self._gps_update(fix)
        self._watch_yaw(fix.t_us)

    def _trusted_gsf_heading(self) -> tuple[float, float] | None:
        found = self.gsf.heading()
        return found if found is not None and found[1] < GSF_TRUST_STD else None

    def _watch_yaw(self, t_us: int) -> None:
        """A heading far from the one GPS velocity alone gives, for seconds, is a lost one
        (a magnetometer that took it, a wrong alignment): take the bank's (PX4's yaw reset)."""
        found = self._trusted_gsf_heading()
        yj = yaw_jacobian(self.q)
        if found is None or yj is None:
            self.gsf_disagree_us = None
            return
        off = abs(math.remainder(found[0] - yj[0], math.tau))
        ins_std = math.sqrt(max(self.P[8, 8], 0.0))
        if off < max(GSF_DISAGREE_RAD, 3.0 * math.hypot(found[1], ins_std)):
            self.gsf_disagree_us = None
            return
        if self.gsf_disagree_us is None:
            self.gsf_disagree_us = t_us
        elif t_us - self.gsf_disagree_us >= GSF_DISAGREE_S * 1e6:
            self._take_gsf_heading(found)

    def _take_gsf_heading(self, found: tuple[float, float]) -> None:
        self._set_yaw(found[0], max(found[1], self.cfg.mag_heading_std))
        self.gsf_disagree_us = None
        self.yaw_resets += 1

    def on_baro(self, reading: Baro) -> None:
        """Barometric height: the vertical channel follows it; GPS only moves its datum."""
        if not self.aligned or not self.baro.due(reading.t_us):
            return
        # Barometric heights are over the curved Earth, the frame is a plane: 6 km out, a
        # height held by the barometer sat 2.8 m above where GPS put it in the frame, and
        # the navigator's height ended 1.9 m above the truth.
        assert self.frame is not None
        drop = self.frame.drop(float(self.p[0]), float(self.p[1]))
        up = self.baro.height(reading.alt_rel_m, reading.t_us, self.p[2] - drop)
        if up is None:
            return
        y = np.array([drop - up - self.p[2]])
        if self._update(y, [2], np.array([[self.cfg.baro_std**2]])):
            self.baro_reject_run = 0
            return
        self.baro_reject_run += 1
        if self.baro_reject_run >= self.cfg.reset_after:
            # The vertical channel ran away (a wild start, a long wrong tilt): rejoin the
            # barometer and let the vertical speed be learnt again.
            self.p[2] = drop - up
            self.v[2] = 0.0
            self._reset_block([2, 5], [self.cfg.baro_std, 2.0])
            self.baro_reject_run = 0
            self.resets += 1

    def on_compass(self, reading: Compass) -> None:
        """Heading update from a digital compass, when no magnetometer speaks.

        The compass levels itself with its accelerometer, so in turns its tilt, and with it
        its heading, is off; how far its tilt is from ours says by how much (the heading
        error is about the tilt error times tan(inclination), ~3 at mid latitudes). Its
        heading is magnetic unless a declination was configured (then the caller made it true).
        """
        self.last_compass = reading
        if not self.aligned or self._fresh(self.last_mag_us, reading.t_us):
            return
        roll, pitch, _ = rot.quaternion_to_euler(self.q)
        tilt_error = math.hypot(reading.roll_rad - roll, reading.pitch_rad - pitch)
        std = math.hypot(self.cfg.compass_std, COMPASS_TILT_TO_HEADING * tilt_error)
        self._heading_update(reading.heading_rad + self._compass_declination(), std)

    def _compass_declination(self) -> float:
        if self.cfg.declination_deg is not None or self.field is None:
            return 0.0
        return self.field.declination

    def on_mag(self, reading: Magnetometer) -> None:
        """Heading update from the magnetometer, levelled with our own attitude, checked
        against the field model and the INS (``ins_mag``)."""
        values = (reading.mx_gauss, reading.my_gauss, reading.mz_gauss)
        if not math.isfinite(sum(values)):
            return
        self.last_mag, self.last_mag_us = np.array(values), reading.t_us
        if not self.aligned or reading.t_us < self.next_heading_us:
            return
        self.next_heading_us = reading.t_us + round(self.cfg.heading_interval_s * 1e6)
        measured = self._mag_heading(self.last_mag)
        yj = yaw_jacobian(self.q)
        if measured is None or yj is None or measured.interfered:
            return
        yaw, h_th = yj
        h = np.zeros(15)
        h[TH] = h_th
        y = math.remainder(measured.heading - yaw, math.tau)
        # Judged against the clean magnetometer's noise, not the disturbance allowance: a
        # heading that is consistently 20° off is not made consistent by doubting it.
        s = self._innovation_var(h, self.cfg.mag_heading_std**2)
        if not self.mag_monitor.observe(reading.t_us, y, s):
            return
        self._heading_update(measured.heading, measured.std)

    def _mag_heading(self, mag: np.ndarray) -> MagHeading | None:
        if self.field is None:
            return None
        roll, pitch, _ = rot.quaternion_to_euler(self.q)
        tilt_std = math.sqrt(max(self.P[6, 6], self.P[7, 7], 0.0))
        return mag_heading(mag, roll, pitch, self.field, self.cfg.mag_heading_std, tilt_std)

    # -- alignment ------------------------------------------------------------------
    def _collect(self, t_us: int, accel: np.ndarray, gyro: np.ndarray) -> None:
        self.t_us = t_us
        self.aligner.add_imu(t_us, accel, gyro)
        fix, compass = self.pending_fix, self.last_compass
        if fix is None or self.field is None:
            return
        fresh = compass is not None and self._fresh(compass.t_us, t_us)
        heading = compass.heading_rad + self._compass_declination() if compass and fresh else None
        mag = self.last_mag if self._fresh(self.last_mag_us, t_us) else None
        vel = np.array((fix.vn_m_s, fix.ve_m_s, fix.vd_m_s))
        found = self.aligner.align(vel, heading, mag, self.field, self.mag_monitor)
        if (warm := self.warm) is not None:
            if found is None and waits_for_alignment(warm, t_us):
                return  # a long gap: the warm start's attitude is the in-air alignment's
            if self._started_warm(warm, fix, t_us, found):
                return
        if found is not None:
            self._start(found, fix, vel)

    def _started_warm(self, warm: WarmState, fix: GpsFix, t_us: int, found: Any) -> bool:
        """In the air, carry on from the last process's solution (ins_warm), aligned."""
        self.warm = None
        s = warm_start(self.frame, self.cfg, self.aligner.samples, warm, fix, t_us, found)
        if s is None:
            return False
        self.p, self.v, self.q, self.P, self.ba, self.bg = s.p, s.v, s.q, s.P, s.ba, s.bg
        self.lag.lag_s, self.aligned, self.t_us = s.gps_lag_s, True, t_us
        self.aligned_us = self.last_gps_us = fix.t_us
        return True

    def _start(self, a: Alignment, fix: GpsFix, vel: np.ndarray) -> None:
        self.p = self._fix_position(fix).tolist()
        self.v = np.nan_to_num(vel).tolist()
        self.q = rot.euler_to_quaternion(a.roll, a.pitch, a.yaw)
        pos_std = self.cfg.fix_pos_std(fix.eph_m)
        c = self.cfg
        diag = [pos_std] * 2 + [pos_std * 1.5] + [max(c.gps_vel_std, 0.5)] * 3
        diag += [a.tilt_std, a.tilt_std, a.yaw_std]
        diag += [c.accel_bias_std] * 3 + [c.gyro_bias_std] * 3
        self.P = np.diag(np.square(diag))
        self.aligned = True
        self.aligned_us = self.last_gps_us = fix.t_us

    # -- updates --------------------------------------------------------------------
    def _fix_position(self, fix: GpsFix) -> np.ndarray:
        assert self.frame is not None
        alt = fix.alt_msl_m if math.isfinite(fix.alt_msl_m) else self.frame.ref[2]
        return self.frame.ned(fix.lat_deg, fix.lon_deg, alt)

    def _gps_update(self, fix: GpsFix) -> None:
        z_p = self._fix_position(fix)
        z_v = np.array((fix.vn_m_s, fix.ve_m_s, fix.vd_m_s))
        if self.cfg.gps_delay_s is None and self._lag_observable(fix.t_us):
            self.lag.observe(fix.t_us, z_v, self.history)
        then = self.history.at(fix.t_us - self.lag.lag_s * 1e6)
        p_then, v_then = then if then is not None else (np.array(self.p), np.array(self.v))
        std = self.cfg.fix_pos_std(fix.eph_m)
        vstd = fix.epv_m if math.isfinite(fix.epv_m) and fix.epv_m > 0 else 1.5 * std
        if self.baro.fresh(fix.t_us):  # the datum follows GPS on the ground only
            self.baro.follow_gps(z_p[2], self.p[2], fix.t_us, self.last_gps_us)
            vstd = max(vstd, self.cfg.gps_vert_with_baro_std)
        rows = [0, 1] + ([2] if math.isfinite(fix.alt_msl_m) else [])
        rows += [3 + i for i in range(3) if math.isfinite(z_v[i])]
        y_all = np.concatenate([z_p - p_then, z_v - v_then])
        c = self.cfg
        vd_std = fix.vd_std_m_s if fix.vd_std_m_s > 0 else c.gps_vel_std  # NaN > 0 is False
        sig = np.array([std, std, vstd, c.gps_vel_std, c.gps_vel_std, vd_std])
        # Just after an alignment in the air the attitude can be tens of degrees off (a
        # start in a pull-up or a roll): GPS is then the truth to converge to, not an
        # outlier to refuse.
        settling = fix.t_us - self.aligned_us < self.cfg.settle_s * 1e6
        ok = self._update(y_all[rows], rows, np.diag(np.square(sig[rows])), gate=not settling)
        self.last_gps_ok = ok
        if ok:
            self.gps_reject_run = 0
            self.last_gps_us = fix.t_us
            return
        self.gps_rejected += 1
        self.gps_reject_run += 1
        if self.gps_reject_run >= self.cfg.reset_after:
            self._reset_to_gps(z_p, z_v, std)

    def _lag_observable(self, t_us: int) -> bool:
        """Is the INS velocity between fixes clean enough to time the GPS by? A vibrating
        IMU's velocity wanders between fixes by more than GPS velocity's own noise, and is
        cleanest just after each update: the fit would then favour lags of a fix period."""
        if self.last_gps_us is None:
            return False
        accel_density, _ = self.noise.densities()
        wander = accel_density * math.sqrt(max(t_us - self.last_gps_us, 0) / 1e6)
        return wander < LAG_MAX_WANDER * self.cfg.gps_vel_std

    def _reset_to_gps(self, z_p: np.ndarray, z_v: np.ndarray, std: float) -> None:
        """The INS has disagreed with GPS for too long: believe GPS, and say so."""
        self.p = z_p.tolist()
        self.v = np.where(np.isfinite(z_v), z_v, self.v).tolist()
        self._reset_block(slice(0, 6), [std] * 3 + [self.cfg.gps_vel_std * 2] * 3)
        self.gps_reject_run = 0
        self.resets += 1
        # An INS that has disagreed with GPS for a second or more has most likely lost its
        # attitude (a heading from a bad magnetometer, a tilt from a wild start): let GPS
        # teach it again (in flight the turns make heading observable). The gate stays: a
        # reset can also follow a run of outliers (multipath), and the next fixes must not
        # be swallowed whole.
        att = np.sqrt(np.maximum(np.diag(self.P)[6:9], 0.0))
        relearn = np.maximum(att, [LOST_TILT_STD, LOST_TILT_STD, LOST_YAW_STD]).tolist()
        self._reset_block([6, 7, 8], relearn)
        found = self._trusted_gsf_heading()
        if found is not None:  # the bank knows the heading: no need to learn it again
            self._take_gsf_heading(found)
            self._reset_block([6, 7], relearn[:2])

    def _heading_update(self, heading: float, std: float) -> None:
        """A yaw-only update: a heading must never tilt the attitude."""
        yj = yaw_jacobian(self.q)
        if yj is None:  # pointing straight up or down: heading undefined
            return
        yaw, h_th = yj
        h = np.zeros((1, 15))
        h[0, TH] = h_th
        y = np.array([math.remainder(heading - yaw, math.tau)])
        ok = self._update(y, h, np.array([[std * std]]), _YAW_ONLY)
        self.last_heading_ok = ok
        if not ok:
            self.heading_rejected += 1

    def _fresh(self, then_us: int | None, now_us: int) -> bool:
        return then_us is not None and (now_us - then_us) / 1e6 < self.cfg.heading_timeout_s
