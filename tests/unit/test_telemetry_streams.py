"""Telemetry streams never break on extreme or missing bus values."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from companion.link.codec import new_encoder, new_parser
from companion.link.telemetry import STREAMS, Snapshot
from companion.messages import GpsFix, Imu, NavFlags, NavState

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
    for stream in STREAMS.values():
        msg = stream.build(mav, snap)  # must not raise, whatever the values
        if msg is not None:
            (decoded,) = new_parser().parse_buffer(msg.pack(mav))
            assert decoded.get_type() == stream.name
