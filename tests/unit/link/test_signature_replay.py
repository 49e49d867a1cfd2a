"""Signed frames on a ``required`` link: the replay table learns a stream's timestamp only
from frames whose signature verified. pymavlink's check stored it first, so one forged
frame with a far-future timestamp on the ground station's (sysid, compid, link id) made
every later real command look replayed: a lock-out by anyone in radio range, no key needed.
"""

from __future__ import annotations

import hashlib

from hypothesis import assume, given, settings
from hypothesis import strategies as st

from companion.link.codec import dialect as d
from companion.link.codec import new_encoder, new_parser
from companion.link.command_service import CommandService, Outcome
from companion.link.endpoints import Endpoint, EndpointOptions
from companion.link.link_router import LinkRouter
from companion.link.signing import configure_parser, shared_state, signing_encoder

KEY = bytes(range(32))
LINK_ID = 1  # the ground station's link id
MINUTE = 6_000_000  # in signing units (10 µs)
FAR_FUTURE = 2**48 - 1


def ground_station(key: bytes = KEY, link_id: int = LINK_ID):
    gcs = new_encoder(255, 190)
    signing_encoder(gcs, key, link_id)
    return gcs


def command(gcs, n: int = 0) -> bytes:
    return gcs.command_long_encode(1, 1, d.MAV_CMD_DO_SET_MODE, 0, 1, n, 0, 0, 0, 0, 0).pack(gcs)


def forged(gcs, n: int, timestamp: int, link_id: int = LINK_ID, sig: bytes = bytes(6)) -> bytes:
    """The ground station's command as someone without the key sends it: any link id,
    timestamp and signature bytes (the checksum does not cover the signature block)."""
    frame = command(gcs, n)
    return frame[:-13] + bytes([link_id]) + timestamp.to_bytes(6, "little") + sig


def signed_parser(state=None):
    parser = new_parser()
    configure_parser(parser.mav, state or shared_state(KEY), "required")
    return parser


def params(messages) -> list[int]:
    return [int(m.param2) for m in messages]


def test_a_forged_future_timestamp_does_not_make_the_real_commands_replays():
    gcs, parser = ground_station(), signed_parser()
    forger = ground_station(key=bytes(32))  # pymavlink signs it, with the wrong key
    forger.signing.timestamp = FAR_FUTURE - 10
    assert params(parser.parse_buffer(command(forger, 1), final=True)) == []
    assert params(parser.parse_buffer(command(gcs, 2), final=True)) == [2]
    assert params(parser.parse_buffer(forged(gcs, 3, FAR_FUTURE), final=True)) == []
    assert params(parser.parse_buffer(command(gcs, 4), final=True)) == [4]
    assert parser.counters.bad_signature == 2 and parser.counters.replayed == 0
    assert FAR_FUTURE - 10 not in parser.mav.signing.stream_timestamps.values()
    assert parser.mav.signing.timestamp < FAR_FUTURE - 10  # ours did not move either


def test_a_correctly_signed_frame_sent_again_is_a_replay():
    gcs, parser = ground_station(), signed_parser()
    frame = command(gcs, 1)
    assert params(parser.parse_buffer(frame, final=True)) == [1]
    assert params(parser.parse_buffer(frame, final=True)) == []
    assert parser.counters.replayed == 1 and parser.counters.bad_signature == 0
    older, newer = command(gcs, 2), command(gcs, 3)
    assert params(parser.parse_buffer(newer + older, final=True)) == [3]  # went backwards
    assert parser.counters.replayed == 2


def test_a_replay_through_another_parser_is_refused_too():
    state = shared_state(KEY)
    gcs, first, second = ground_station(), signed_parser(state), signed_parser(state)
    frame = command(gcs, 1)
    assert params(first.parse_buffer(frame, final=True)) == [1]
    assert params(second.parse_buffer(frame, final=True)) == []
    assert second.counters.replayed == 1


def test_a_timestamp_more_than_a_minute_behind_ours_is_refused():
    """The spec's accept rules: a new stream, or any stream once another correctly signed
    one has moved our timestamp on, is refused more than a minute behind it."""
    gcs, parser = ground_station(), signed_parser()
    now = parser.mav.signing.timestamp
    gcs.signing.timestamp = now - MINUTE - 10
    assert params(parser.parse_buffer(command(gcs, 1), final=True)) == []
    assert parser.counters.replayed == 1
    gcs.signing.timestamp = now - MINUTE + 10
    assert params(parser.parse_buffer(command(gcs, 2), final=True)) == [2]
    other = ground_station(link_id=2)  # a second key holder whose clock runs ahead
    other.signing.timestamp = now + 2 * MINUTE
    assert params(parser.parse_buffer(command(other, 3), final=True)) == [3]
    assert parser.mav.signing.timestamp == now + 2 * MINUTE
    assert params(parser.parse_buffer(command(gcs, 4), final=True)) == []
    assert parser.counters.replayed == 2


@settings(max_examples=200, deadline=None)
@given(
    link_id=st.integers(0, 255),
    timestamp=st.integers(0, 2**48 - 1),
    sig=st.binary(min_size=6, max_size=6),
)
def test_no_forged_signature_changes_what_the_real_ground_station_can_send(link_id, timestamp, sig):
    gcs, parser = ground_station(), signed_parser()
    frame = forged(gcs, 1, timestamp, link_id, sig)
    assume(hashlib.sha256(KEY + frame[:-6]).digest()[:6] != sig)
    before = dict(parser.mav.signing.stream_timestamps), parser.mav.signing.timestamp
    assert params(parser.parse_buffer(frame, final=True)) == []
    assert parser.counters.bad_signature == 1 and parser.counters.rejected == 1
    assert (dict(parser.mav.signing.stream_timestamps), parser.mav.signing.timestamp) == before
    assert params(parser.parse_buffer(command(gcs, 2), final=True)) == [2]


class Radio(Endpoint):
    """A serial radio in memory: what arrives is queued by the test, what is sent kept."""

    def __init__(self) -> None:
        super().__init__("serial:///dev/null:57600")
        self.options = EndpointOptions(signing="required")
        self.inbox: list[bytes] = []
        self.sent: list[bytes] = []

    def filenos(self) -> list[int]:
        return [0]

    def read_ready(self, fd: int) -> list[tuple[object, bytes]]:
        data, self.inbox = self.inbox, []
        return [(None, b"".join(data))]

    def send(self, data: bytes) -> int:
        self.sent.append(bytes(data))
        return len(data)

    def close(self) -> None:
        pass


def test_the_ground_station_is_answered_after_a_forged_future_timestamp_on_its_link():
    vehicle = new_encoder(1, 1)
    commands = CommandService(vehicle, 1, 1)
    commands.register(d.MAV_CMD_DO_SET_MODE, lambda args: Outcome())
    radio = Radio()
    router = LinkRouter(vehicle, [radio], [commands], signing_key=KEY)
    listener = signed_parser()  # the ground station's own parser, with the key

    def exchange(frame: bytes) -> list[int]:
        radio.inbox.append(frame)
        router.receive(radio, 0, 0.0)
        got = [m for raw in radio.sent for m in listener.parse_buffer(raw, final=True)]
        radio.sent.clear()
        return [m.result for m in got if m.get_type() == "COMMAND_ACK"]

    gcs = ground_station()
    assert exchange(command(gcs, 1)) == [d.MAV_RESULT_ACCEPTED]
    bad_before = router.counters.bad
    assert exchange(forged(gcs, 2, FAR_FUTURE)) == []  # no key: not acted on
    assert router.counters.bad == bad_before + 1
    assert exchange(command(gcs, 3)) == [d.MAV_RESULT_ACCEPTED]  # not locked out
    replay = command(gcs, 4)
    assert exchange(replay) == [d.MAV_RESULT_ACCEPTED]
    assert exchange(replay) == []  # the same signed frame again
    assert router.counters.bad == bad_before + 2
    assert router.counters.bad_signature == 1 and router.counters.replayed == 1
