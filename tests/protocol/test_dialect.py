"""The committed dialect module is what mavgen makes of companion.xml, and it works."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import all as all_dialect
from pymavlink.dialects.v20 import ardupilotmega

from mavlink_dialect import companion as dialect
from mavlink_dialect.generate import HERE, generate


def test_committed_module_matches_the_xml(tmp_path):
    fresh = tmp_path / "companion.py"
    generate(fresh)
    committed = (HERE / "companion.py").read_text()
    assert fresh.read_text() == committed, (
        "mavlink_dialect/companion.py is stale: run `uv run python -m mavlink_dialect.generate`"
    )


@pytest.mark.parametrize("signed", [False, True])
def test_own_messages_round_trip(signed):
    sender = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    receiver = dialect.MAVLink(None)
    if signed:
        key = bytes(range(32))
        sender.signing.secret_key = key
        sender.signing.sign_outgoing = True
        receiver.signing.secret_key = key
    health = sender.plugin_health_encode(1000, 42, 1, 500, 3, 7, 12.5, 830.0, 0, 4, 2, b"gps")
    nav = sender.nav_status_encode(
        1000, 15, 2, 0, [1.0, 1.1, 2.0], [0.1, 0.1, 0.2], [0.01, 0.01, 0.03], 0.0, b"ins_ekf"
    )
    got = receiver.parse_buffer(health.pack(sender) + nav.pack(sender))
    assert [m.get_type() for m in got] == ["PLUGIN_HEALTH", "NAV_STATUS"]
    assert got[0].name == "gps" and got[0].restarts == 1 and got[0].cpu == 12.5
    assert got[1].navigator == "ins_ekf" and list(got[1].pos_std) == pytest.approx([1.0, 1.1, 2.0])


# Message id ranges mavlink/mavlink's all.xml allocates or reserves (July 2026), beyond what
# the all.xml pymavlink ships says: every dialect on a network must stay out of them.
ALLOCATED = [(300, 10000), (8000, 8999), (10001, 10999), (11000, 11999), (42000, 42999),
             (50000, 50099), (51000, 51999), (52000, 52099), (52100, 52499), (52500, 52599),
             (52600, 52609), (53000, 53999), (60000, 60049), (60050, 60099)]  # fmt: skip


def _own_ids() -> list[int]:
    xml = (HERE / "companion.xml").read_text()
    upstream = (300, 395, 397)  # upstream messages the shipped common.xml lacks
    return [int(i) for i in re.findall(r'<message id="(\d+)"', xml) if int(i) not in upstream]


def test_ids_of_our_own_clash_with_no_dialect_mavlink_knows():
    shipped = (Path(all_dialect.__file__).with_suffix(".xml")).read_text()
    ranges = ALLOCATED + [
        (int(a), int(b)) for a, b in re.findall(r"messages:\s*(\d+)\s*-\s*(\d+)", shipped)
    ]
    own = _own_ids()
    assert own == [dialect.MAVLINK_MSG_ID_PLUGIN_HEALTH, dialect.MAVLINK_MSG_ID_NAV_STATUS]
    for msg_id in own:
        assert msg_id not in all_dialect.mavlink_map
        assert not [r for r in ranges if r[0] <= msg_id <= r[1]], msg_id
        assert msg_id < 2**16  # MESSAGE_INTERVAL names a message in 16 bits
    assert dialect.MAVLINK_MSG_ID_AVAILABLE_MODES == 435


@pytest.mark.parametrize("other", [ardupilotmega, all_dialect])
def test_a_tool_speaking_another_dialect_sees_our_messages_as_unknown_not_bad(other):
    # MAVProxy and Mission Planner speak ardupilotmega: a frame of ours whose id they know
    # as something else fails their CRC, is counted as bad data, and looks like link loss.
    sender = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    health = sender.plugin_health_encode(1000, 42, 1, 500, 3, 7, 12.5, 830.0, 0, 4, 2, b"gps")
    nav = sender.nav_status_encode(
        1000, 15, 2, 0, [1.0, 1.1, 2.0], [0.1, 0.1, 0.2], [0.01, 0.01, 0.03], 0.0, b"ins_ekf"
    )
    beat = sender.heartbeat_encode(1, 12, 0, 0, 3)
    wire = b"".join(m.pack(sender) for m in (health, nav, beat))
    receiver = other.MAVLink(None)
    got = [m.get_type() for m in receiver.parse_buffer(wire)]
    assert "BAD_DATA" not in got
    assert got[-1] == "HEARTBEAT" and len(got) == 3


def test_protocol_version_is_mavlink2_only():
    from companion.link.codec import new_encoder, new_parser
    from companion.link.identity import IdentityService

    mav = new_encoder(1)
    identity = IdentityService(mav, 1, dialect.MAV_AUTOPILOT_GENERIC, 0)
    (msg,) = new_parser().parse_buffer(identity.protocol_version().pack(mav))
    assert (msg.version, msg.min_version, msg.max_version) == (200, 100, 200)


def test_component_information_messages_are_wire_compatible_with_upstream():
    # CRC_EXTRA of upstream common.xml: a different field list would make QGroundControl
    # drop every COMPONENT_METADATA the vehicle sends.
    assert dialect.MAVLink_component_metadata_message.crc_extra == 182
    assert dialect.MAVLink_component_information_message.crc_extra == 0
    assert dialect.MAVLINK_MSG_ID_COMPONENT_METADATA == 397
    assert dialect.MAVLINK_MSG_ID_COMPONENT_INFORMATION == 395
