"""The MAVLink shell under hostile SERIAL_CONTROL: any device, flags, count and bytes are
answered or dropped and counted, never raised; what it sends is text a terminal shows."""

from __future__ import annotations

from types import SimpleNamespace

from hypothesis import given, settings
from hypothesis import strategies as st

from companion.link.codec import new_encoder
from companion.link.microservice import Peer
from companion.link.shell_service import CHUNK, MAX_LINE, ShellService
from companion.params import ParamDecl, ParamStore
from mavlink_dialect import companion as m

PEER = Peer(255, 190, 0)
message = st.builds(
    SimpleNamespace,
    device=st.sampled_from([m.SERIAL_CONTROL_DEV_SHELL, m.SERIAL_CONTROL_DEV_GPS1, 200]),
    flags=st.integers(0, 255),
    count=st.integers(0, 255),
    data=st.binary(min_size=70, max_size=70).map(list),
)


@settings(max_examples=300, deadline=None)
@given(st.lists(message, max_size=12))
def test_any_serial_control_is_answered_or_counted_never_raised(msgs):
    shell = ShellService(new_encoder(1, 1), lambda: None, ParamStore([ParamDecl("X", 1.0)]))
    for msg in msgs:
        for out in shell.handle(msg, PEER, 0.0):
            reply = out.msg
            assert reply.flags == m.SERIAL_CONTROL_FLAG_REPLY and out.to == PEER
            assert 0 < reply.count <= CHUNK
            text = bytes(reply.data[: reply.count]).decode("ascii")
            assert all(0x20 <= ord(c) < 0x7F or c in "\n\b" for c in text), repr(text)
        assert len(shell.line) <= MAX_LINE
