"""The simulated receiver's RTCM3 input: whole frames counted by type, the rest as bad."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from pyrtcm import RTCMMessage

from bridges.jsbsim.rtcm_listener import RtcmListener


def rtcm3(kind: int, payload_bytes: int) -> bytes:
    payload = bytearray(payload_bytes)
    payload[0], payload[1] = kind >> 4, (kind & 0xF) << 4
    return RTCMMessage(payload=bytes(payload)).serialize()


def test_frames_split_anywhere_are_counted_once_each_by_type():
    stream = rtcm3(1005, 19) + rtcm3(4072, 500) + rtcm3(1230, 6)
    listener = RtcmListener()
    good = sum(listener.feed(stream[i : i + 7], 0.2 * i) for i in range(0, len(stream), 7))
    assert good == 3 and dict(listener.types) == {1005: 1, 4072: 1, 1230: 1}
    assert listener.bad == 0 and listener.last_good_s > 0


def test_garbage_and_a_broken_frame_are_counted_and_the_next_frame_is_still_found():
    broken = bytearray(rtcm3(1005, 19))
    broken[10] ^= 0xFF  # its CRC no longer matches
    listener = RtcmListener()
    assert listener.feed(b"$GPGGA,junk\r\n" + bytes(broken) + rtcm3(1077, 40), 1.0) == 1
    assert dict(listener.types) == {1077: 1} and listener.bad >= 2
    assert "1 messages (1077 x1)" in listener.summary()


@given(st.lists(st.binary(max_size=300), max_size=20))
def test_any_bytes_at_all_never_raise(chunks):
    listener = RtcmListener()
    for chunk in chunks:
        listener.feed(chunk, 0.0)
    assert listener.messages >= 0
