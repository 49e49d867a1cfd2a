"""ATTITUDE_TARGET says the controller's roll and pitch demands; HIGHRES_IMU the IMU."""

from __future__ import annotations

import math

import pytest

from companion.link.codec import dialect as d
from companion.link.rate_messages import attitude_target, highres_imu
from companion.link.snapshot import Snapshot
from companion.messages import ControlStatus, Imu, NavState


def _euler(q) -> tuple[float, float, float]:
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(2 * (w * y - z * x))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def test_attitude_target_is_the_controllers_demand_at_the_present_heading():
    mav = d.MAVLink(None, 1, 1)
    snap = Snapshot(time_boot_ms=1234)
    assert attitude_target(mav, snap) is None  # no controller running: nothing to say
    snap.nav = NavState(yaw_rad=1.2)
    snap.control = ControlStatus(nav_roll_rad=0.3, nav_pitch_rad=-0.1, throttle=0.7)
    msg = attitude_target(mav, snap)
    assert _euler(msg.q) == pytest.approx((0.3, -0.1, 1.2), abs=1e-6)
    assert msg.thrust == pytest.approx(0.7) and msg.time_boot_ms == 1234
    assert msg.type_mask & d.ATTITUDE_TARGET_TYPEMASK_BODY_ROLL_RATE_IGNORE


def test_highres_imu_marks_only_what_it_has():
    mav = d.MAVLink(None, 1, 1)
    snap = Snapshot(imu=Imu(t_us=5, ax_m_s2=1.0, az_m_s2=-9.8, temp_c=math.nan))
    msg = highres_imu(mav, snap)
    assert (msg.xacc, msg.zacc) == (1.0, pytest.approx(-9.8))
    assert msg.fields_updated & d.HIGHRES_IMU_UPDATED_ZACC
    assert not msg.fields_updated & (d.HIGHRES_IMU_UPDATED_TEMPERATURE | d.HIGHRES_IMU_UPDATED_XMAG)
