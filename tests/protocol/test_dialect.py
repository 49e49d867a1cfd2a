"""The committed dialect module is what mavgen makes of companion.xml, and it works."""

from __future__ import annotations

from pathlib import Path

import pytest

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
    assert dialect.MAVLINK_MSG_ID_PLUGIN_HEALTH == 52000


def test_ids_of_our_own_are_in_the_private_range():
    xml = Path(HERE / "companion.xml").read_text()
    assert 'id="52000"' in xml and 'id="52001"' in xml
    assert dialect.MAVLINK_MSG_ID_AVAILABLE_MODES == 435


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
