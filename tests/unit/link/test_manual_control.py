"""MANUAL_CONTROL as QGroundControl sends it, decoded from the wire, and hostile values."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from companion.link.codec import new_encoder, new_parser
from companion.link.manual_control import ManualControlService
from companion.link.microservice import Peer
from companion.messages import PilotInput, PilotSource

PEER = Peer(255, 190, 0)
INT16 = st.integers(-32768, 32767)


def wire(x: int, y: int, z: int, r: int, target: int = 1):
    """The message as it arrives: packed by QGroundControl's sysid, parsed by the vehicle."""
    gcs = new_encoder(255, 190)
    data = gcs.manual_control_encode(target, x, y, z, r, 0).pack(gcs)
    (msg,) = new_parser().parse_buffer(data)
    return msg


def service() -> tuple[ManualControlService, list[PilotInput], list[str]]:
    got: list[PilotInput] = []
    texts: list[str] = []
    return ManualControlService(1, got.append, lambda: 42, texts.append), got, texts


def test_axes_become_sticks_with_pitch_forward_nose_down():
    svc, got, _ = service()
    svc.handle(wire(x=400, y=-500, z=700, r=250), PEER, 0.0)
    (p,) = got
    assert (p.pitch, p.roll, p.yaw, p.throttle) == (-0.4, -0.5, 0.25, 0.7)
    assert (p.t_us, p.source, p.mode_switch) == (42, PilotSource.MANUAL_CONTROL, -1)
    assert p.usable()


def test_an_axis_the_joystick_lacks_is_centred_and_another_vehicle_is_ignored():
    svc, got, _ = service()
    svc.handle(wire(x=32767, y=32767, z=32767, r=32767), PEER, 0.0)
    assert (got[0].pitch, got[0].roll, got[0].yaw, got[0].throttle) == (0.0, 0.0, 0.0, 0.0)
    svc.handle(wire(0, 0, 500, 0, target=2), PEER, 0.0)
    assert len(got) == 1 and svc.refused == 0


def test_past_full_travel_is_refused_counted_and_told():
    svc, got, texts = service()
    for axes in [
        (1001, 0, 0, 0),
        (0, -1001, 0, 0),
        (0, 0, -1, 0),
        (0, 0, 1001, 0),
        (0, 0, 0, -32768),
    ]:
        svc.handle(wire(*axes), PEER, 0.0)
    assert got == [] and svc.refused == 5
    assert "x 1001 outside" in texts[0]


@given(INT16, INT16, INT16, INT16)
def test_any_values_give_sticks_in_range_or_a_refusal(x, y, z, r):
    svc, got, _ = service()
    svc.handle(wire(x, y, z, r), PEER, 0.0)
    assert len(got) + svc.refused == 1
    for p in got:
        assert all(-1.0 <= v <= 1.0 for v in (p.pitch, p.roll, p.yaw)) and 0 <= p.throttle <= 1
