"""A running vehicle under a hostile ground station's stream on UDP: nothing restarts,
every command is answered, telemetry goes on, the stored mission and parameters stay."""

from __future__ import annotations

import hashlib
import time
from collections import Counter
from pathlib import Path

from companion.link.command_service import CommandService
from companion.link.gcs_watch import GcsWatch
from companion.link.log_transfer import LogTransferService
from companion.link.manual_control import ManualControlService
from companion.link.metadata_service import MetadataService
from companion.link.mission_service import MissionService
from companion.link.params_service import ParamsService
from companion.link.timesync import TimesyncService
from companion.messages import PluginState
from mavlink_dialect import companion as d
from tests.protocol.mav_client import GroundStation, free_udp_port, upload_mission
from tests.support.configs import client_vehicle
from tests.support.hostile import HOSTILE_TYPES, HostileStream
from tests.support.vehicle import wait_for

FRAMES = 6000
BURST = 40  # frames sent between reads of what came back


SERVICES = (
    CommandService, GcsWatch, LogTransferService, ManualControlService, MetadataService,
    MissionService, ParamsService, TimesyncService,
)  # fmt: skip
BY_DESIGN = {"LOG_ERASE", "MISSION_CLEAR_ALL"}  # they change the vehicle: never sent


def test_the_stream_carries_every_message_the_link_accepts_but_erase_and_clear():
    accepted = set().union(*(service.handles for service in SERVICES))
    assert accepted - BY_DESIGN == HOSTILE_TYPES
    parser, stream = d.MAVLink(None), HostileStream(seed=3)
    parser.robust_parsing = True
    kinds: Counter[str] = Counter()
    for _ in range(20_000):
        frame = stream.frame()
        if frame.kind == "hostile":
            kinds.update(msg.get_type() for msg in parser.parse_buffer(frame.data) or [])
    assert set(kinds) == HOSTILE_TYPES
    assert not BY_DESIGN & set(kinds)


def state_digest(state: Path) -> dict[str, str]:
    """Every stored file (missions, parameters) by its SHA-256."""
    files = sorted(p for p in state.rglob("*") if p.is_file())
    return {str(p.relative_to(state)): hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


def drain(gcs: GroundStation, acks: Counter, seen: Counter) -> None:
    while (msg := gcs.conn.recv_match(blocking=False)) is not None:
        seen[msg.get_type()] += 1
        if msg.get_type() == "COMMAND_ACK":
            acks[msg.command] += 1


def all_answered(gcs: GroundStation, sent: Counter, acks: Counter, seen: Counter) -> None:
    try:
        answered = lambda: drain(gcs, acks, seen) or acks == sent  # noqa: E731
        wait_for(answered, 20, "an answer to every command", period_s=0.005)
    except AssertionError:
        missing = {c: (n, acks[c]) for c, n in sent.items() if acks[c] != n}
        raise AssertionError(f"sent vs answered: {missing}; seen {dict(seen)}") from None


def attitude_rate(gcs: GroundStation, seconds: float) -> float:
    count, end = 0, time.monotonic() + seconds
    while time.monotonic() < end:
        if gcs.conn.recv_match(type="ATTITUDE", blocking=True, timeout=0.1) is not None:
            count += 1
    return count / seconds


def test_a_hostile_stream_changes_nothing_and_every_command_is_answered(vehicle_factory, tmp_path):
    port, state = free_udp_port(), tmp_path / "state"
    vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", state))
    gcs = GroundStation(port)
    gcs.connect()
    upload_mission(gcs)
    gcs.mav.param_set_send(1, 1, b"SR_GPS", 3.0, 9)
    gcs.recv("PARAM_VALUE", param_id="SR_GPS", param_value=3.0)
    before = state_digest(state)
    assert any("mission" in name for name in before) and "params.json" in before
    rate_before = attitude_rate(gcs, 2.0)

    stream, sent, acks, seen = HostileStream(seed=7), Counter(), Counter(), Counter()
    for i in range(FRAMES):
        frame = stream.frame()
        gcs.conn.port.sendto(frame.data, gcs.conn.destination_addr)
        if frame.command is not None:
            sent[frame.command] += 1
        if i % BURST == BURST - 1 or i == FRAMES - 1:
            # Each burst's commands answered before the next, as a ground station waits for
            # its acks: a link process starved by a busy machine then never has more than a
            # burst queued, and the kernel's socket buffer never drops a datagram.
            all_answered(gcs, sent, acks, seen)

    wait_for(lambda: vehicle.row("link").refused > 0, 10, "the link's refusals counted")
    rows = {row.name.decode(): row for row in vehicle.health().rows()}
    assert {name: row.restarts for name, row in rows.items()} == dict.fromkeys(rows, 0)
    core = [row for row in rows.values() if row.group.decode() == "core"]
    assert all(row.state == PluginState.RUNNING for row in core)
    assert rows["flight"].state == PluginState.STOPPED  # nothing armed the vehicle
    assert rows["link"].frames_bad > 0 and rows["link"].refused > 0
    assert seen["ATTITUDE"] > 0  # telemetry went on during the stream
    assert attitude_rate(gcs, 2.0) >= 0.5 * rate_before
    assert state_digest(state) == before
    gcs.mav.mission_request_list_send(1, 1, d.MAV_MISSION_TYPE_MISSION)
    assert gcs.recv("MISSION_COUNT", 5, mission_type=0).count == 2
    gcs.close()
