"""The channel registry is the one list: the flight log and the link's telemetry derive
theirs from it."""

from __future__ import annotations

from typing import get_type_hints

from companion.link.snapshot import SNAPSHOT_CHANNELS, Snapshot
from companion.messages.channels import CHANNELS, LOGGED
from companion.plugins.link.mavlink_link import MavlinkLink
from companion.plugins.system.logger import LoggerPlugin


def test_the_flight_log_records_every_channel_but_those_that_say_why_not():
    recorded = LoggerPlugin.settings["channels"].default
    assert list(recorded) == list(LOGGED)
    assert "sensors/range" in recorded  # a landing's log has the rangefinder's readings
    left_out = {name: c.unlogged for name, c in CHANNELS.items() if name not in recorded}
    assert left_out.keys() == {"sensors/rc_switch", "sim/truth", "sim/clock",
                               "system/plugin_stats", "system/logged",
                               "link/gps_inject"}  # fmt: skip
    assert all(len(reason) > 20 for reason in left_out.values()), left_out


def test_each_snapshot_field_holds_its_channels_payload_and_the_link_reads_it():
    hints = get_type_hints(Snapshot)
    for field, name in SNAPSHOT_CHANNELS.items():
        assert hints[field] == CHANNELS[name].type | None, field
    assert set(SNAPSHOT_CHANNELS.values()) <= set(MavlinkLink.optional_inputs)
    assert SNAPSHOT_CHANNELS["rangefinder"] == "sensors/range"
