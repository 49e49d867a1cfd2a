"""Telemetry streams never break on extreme or missing bus values."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from companion.link.codec import new_encoder, new_parser
from companion.link.telemetry import STREAMS, Snapshot
from companion.messages import ControlStatus, GpsFix, Imu, NavFlags, NavState

floats = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=400, deadline=None)
@given(
    ax=floats, gz=floats, roll=floats, lat=floats, vn=floats, alt=floats, speed=floats, yaw=floats
)
def test_every_stream_encodes_whatever_the_sensors_say(ax, gz, roll, lat, vn, alt, speed, yaw):
    mav = new_encoder(1)
    nav = NavState(t_us=1, roll_rad=roll, yaw_rad=yaw, lat_deg=lat, vn_m_s=vn, alt_msl_m=alt)
    nav.flags = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID)
    gps = GpsFix(t_us=1, lat_deg=lat, alt_msl_m=alt, ground_speed_m_s=speed, hdop=speed)
    gps.course_rad = yaw
    snap = Snapshot(time_boot_ms=5, nav=nav, imu=Imu(t_us=1, ax_m_s2=ax, gz_rad_s=gz), gps=gps)
    snap.control = ControlStatus(t_us=1, airspeed_m_s=speed, throttle=roll)
    for stream in STREAMS.values():
        msg = stream.build(mav, snap)  # must not raise, whatever the values
        if msg is not None:
            (decoded,) = new_parser().parse_buffer(msg.pack(mav))
            assert decoded.get_type() == stream.name


def test_vfr_hud_shows_the_estimated_airspeed_and_the_throttle_in_flight():
    mav = new_encoder(1)
    nav = NavState(t_us=1, vn_m_s=20.0, ve_m_s=0.0, alt_msl_m=150.0)
    snap = Snapshot(nav=nav)
    on_ground = STREAMS[74].build(mav, snap)  # no flight controller: ground speed, idle
    assert (on_ground.airspeed, on_ground.groundspeed, on_ground.throttle) == (20.0, 20.0, 0)
    snap.control = ControlStatus(t_us=1, airspeed_m_s=24.5, throttle=0.62)
    flying = STREAMS[74].build(mav, snap)  # into a 4.5 m/s head wind
    assert (flying.airspeed, flying.groundspeed, flying.throttle) == (24.5, 20.0, 62)
