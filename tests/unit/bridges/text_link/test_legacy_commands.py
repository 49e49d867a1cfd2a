"""START and STOP as COMMAND_LONGs: arm/disarm parameters, retransmission with the
confirmation counted up, acks that end or pause a command, the optional mission start
after an accepted arm, and the latest word from the ground station winning."""

from __future__ import annotations

import math

import pytest

from bridges.text_link.commands import CommandSender
from mavlink_dialect import companion as mavlink

ARM = mavlink.MAV_CMD_COMPONENT_ARM_DISARM
MISSION_START = mavlink.MAV_CMD_MISSION_START


def sends(sender, until_s, step_s=0.25, from_s=0.0):
    """Tick every ``step_s`` from ``from_s`` up to (not at) ``until_s``; the (time,
    CommandLong) of each send. Quarter seconds add up exactly in binary."""
    out = []
    for i in range(math.ceil((until_s - from_s) / step_s)):
        now = from_s + i * step_s
        cmd = sender.tick(now)
        if cmd is not None:
            out.append((now, cmd))
    return out


def results(sender):
    return [(o.word, o.label, o.result) for o in sender.outcomes]


def test_start_arms():
    sender = CommandSender()
    sender.request("START", 0.0)
    cmd = sender.tick(0.0)
    assert cmd is not None
    assert (cmd.command, tuple(cmd.params), cmd.confirmation) == (400, (1.0, 0.0), 0)


def test_an_unanswered_command_is_sent_again_with_the_confirmation_counted_up():
    sender = CommandSender(retry_s=1.0, attempts=4)
    sender.request("START", 0.0)
    out = sends(sender, 3.5)
    assert [t for t, _ in out] == [0.0, 1.0, 2.0, 3.0]
    assert [c.confirmation for _, c in out] == [0, 1, 2, 3]
    assert {(c.command, tuple(c.params)) for _, c in out} == {(ARM, (1.0, 0.0))}


def test_no_ack_after_every_attempt_ends_the_command():
    sender = CommandSender(retry_s=1.0, attempts=4)
    sender.request("START", 0.0)
    assert len(sends(sender, 3.9)) == 4
    assert list(sender.outcomes) == []
    assert sends(sender, 10.0, from_s=4.0) == []
    assert results(sender) == [("START", "arm", "NO_ACK")]
    assert sender.pending is None


def test_an_accepted_ack_ends_the_command():
    sender = CommandSender()
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(ARM, mavlink.MAV_RESULT_ACCEPTED, 0.2)
    assert results(sender) == [("START", "arm", "MAV_RESULT_ACCEPTED")]
    assert sends(sender, 10.0, from_s=0.2) == []


def test_stop_disarms():
    sender = CommandSender()
    sender.request("STOP", 0.0)
    cmd = sender.tick(0.0)
    assert (cmd.command, tuple(cmd.params), cmd.confirmation) == (ARM, (0.0, 0.0), 0)


def test_a_forced_stop_carries_the_magic_number():
    sender = CommandSender(force_stop=True)
    sender.request("STOP", 0.0)
    cmd = sender.tick(0.0)
    assert (cmd.command, tuple(cmd.params)) == (ARM, (0.0, 21196.0))
    sender.on_ack(ARM, mavlink.MAV_RESULT_ACCEPTED, 0.1)
    assert results(sender) == [("STOP", "forced disarm", "MAV_RESULT_ACCEPTED")]


def test_in_progress_stops_retransmission_until_the_final_answer():
    sender = CommandSender(retry_s=1.0)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(ARM, mavlink.MAV_RESULT_IN_PROGRESS, 0.3)
    assert sends(sender, 10.0, from_s=0.3) == []
    assert list(sender.outcomes) == []
    sender.on_ack(ARM, mavlink.MAV_RESULT_ACCEPTED, 10.5)
    assert results(sender) == [("START", "arm", "MAV_RESULT_ACCEPTED")]


def test_in_progress_without_a_final_answer_ends_unanswered():
    sender = CommandSender(retry_s=1.0)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(ARM, mavlink.MAV_RESULT_IN_PROGRESS, 0.5)
    assert sends(sender, 11.0, from_s=0.5) == []
    assert results(sender) == [("START", "arm", "NO_FINAL_ACK")]


def test_an_ack_for_another_command_is_ignored():
    sender = CommandSender(retry_s=1.0)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(MISSION_START, mavlink.MAV_RESULT_ACCEPTED, 0.2)
    assert list(sender.outcomes) == []
    cmd = sender.tick(1.0)
    assert (cmd.command, cmd.confirmation) == (ARM, 1)


def test_an_ack_with_nothing_pending_is_ignored():
    sender = CommandSender()
    sender.on_ack(ARM, mavlink.MAV_RESULT_ACCEPTED, 0.0)
    assert list(sender.outcomes) == []
    assert sender.tick(0.0) is None


def test_an_accepted_arm_starts_the_mission_when_asked():
    sender = CommandSender(start_mission=True)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(ARM, mavlink.MAV_RESULT_ACCEPTED, 0.2)
    cmd = sender.tick(0.2)
    assert (cmd.command, cmd.confirmation) == (MISSION_START, 0)
    sender.on_ack(MISSION_START, mavlink.MAV_RESULT_ACCEPTED, 0.3)
    assert results(sender) == [
        ("START", "arm", "MAV_RESULT_ACCEPTED"),
        ("START", "mission start", "MAV_RESULT_ACCEPTED"),
    ]


def test_a_denied_arm_starts_no_mission():
    sender = CommandSender(start_mission=True)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(ARM, mavlink.MAV_RESULT_DENIED, 0.2)
    assert results(sender) == [("START", "arm", "MAV_RESULT_DENIED")]
    assert sends(sender, 10.0, from_s=0.2) == []


def test_no_mission_start_unless_asked():
    sender = CommandSender(start_mission=False)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.on_ack(ARM, mavlink.MAV_RESULT_ACCEPTED, 0.2)
    assert sends(sender, 10.0, from_s=0.2) == []


def test_stop_while_start_is_pending_supersedes_it():
    sender = CommandSender(retry_s=1.0)
    sender.request("START", 0.0)
    sender.tick(0.0)
    sender.request("STOP", 0.5)
    assert results(sender) == [("START", "arm", "SUPERSEDED")]
    cmd = sender.tick(0.5)
    assert (cmd.command, tuple(cmd.params), cmd.confirmation) == (ARM, (0.0, 0.0), 0)


def test_an_unknown_word_is_refused():
    sender = CommandSender()
    with pytest.raises(ValueError, match="HELLO"):
        sender.request("HELLO", 0.0)
    assert sender.tick(0.0) is None


def test_an_unknown_word_leaves_a_pending_command_alone():
    sender = CommandSender()
    sender.request("START", 0.0)
    with pytest.raises(ValueError):
        sender.request("HELLO", 0.1)
    assert list(sender.outcomes) == []
    assert sender.tick(0.1) is not None
