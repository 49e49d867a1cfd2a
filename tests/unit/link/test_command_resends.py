"""A command resent before its answer, and one for a flight plug-in that is still starting.

MAVSDK resends a command it has no answer to every 0.5 s, with confirmation 0 each time: a
grab, a photo or a servo set handed to a flight plug-in must still be done once, and the
sender answered once, by the first's final ack (MAVSDK's Gripper plug-in takes an
IN_PROGRESS for the final result). Right after arming, the flight
plug-ins run before they have made their readers: a command for one is held in the link
until it has reported since the flight group started, not put on the bus to be lost.
"""

from __future__ import annotations

import math

from companion.link.codec import new_encoder
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.held import HeldCommands
from companion.link.microservice import Peer
from companion.messages import PluginState, SystemHealth, VehicleCommand
from mavlink_dialect import companion as d

GCS = Peer(245, 190, 0)
CONTROLLER = b"control.fixed_wing"


def deferring_service() -> tuple[CommandService, list[tuple[float, ...]]]:
    """A service whose one command is handed on and answered later, as DO_GRIPPER is."""
    service = CommandService(new_encoder(1, 1), 1, 1)
    done: list[tuple[float, ...]] = []

    def hand_on(args: CommandArgs) -> Outcome:
        done.append(args.params)
        return Outcome(defer_seq=len(done), timeout_s=10.0)

    service.register(d.MAV_CMD_DO_GRIPPER, hand_on)
    return service, done


def gripper(action: float, confirmation: int = 0) -> CommandArgs:
    nan = math.nan  # MAVSDK's unused parameters
    return CommandArgs(
        d.MAV_CMD_DO_GRIPPER, (1.0, action, nan, nan, nan, nan, nan), confirmation, GCS
    )


def results(out) -> list[int]:
    return [o.msg.result for o in out]


def test_a_resend_while_in_progress_is_done_once_and_answered_once():
    service, done = deferring_service()
    assert service.dispatch(gripper(1.0), 0.0) == []  # handed on
    assert service.dispatch(gripper(1.0), 0.5) == []  # MAVSDK's resend
    assert service.dispatch(gripper(1.0, confirmation=1), 1.0) == []
    assert len(done) == 1
    assert results(service.complete(1, d.MAV_RESULT_ACCEPTED, 1.2)) == [d.MAV_RESULT_ACCEPTED]
    again = service.dispatch(gripper(1.0, confirmation=2), 1.5)  # a late resend: the same
    assert results(again) == [d.MAV_RESULT_ACCEPTED] and len(done) == 1
    service.dispatch(gripper(1.0), 2.0)  # answered: the same again is a new command
    assert len(done) == 2


def test_another_command_of_the_same_kind_is_not_a_resend():
    service, done = deferring_service()
    service.dispatch(gripper(1.0), 0.0)
    assert service.dispatch(gripper(0.0), 0.1) == []  # a release after the grab: its own
    assert [p[1] for p in done] == [1.0, 0.0]


def health(running: bool, counted_us: int) -> SystemHealth:
    table = SystemHealth(count=1, flight_running=int(running))
    row = table.plugins[0]
    row.kind, row.counted_us, row.group = CONTROLLER, counted_us, b"flight"
    row.state = int(PluginState.RUNNING if running else PluginState.STOPPED)
    return table


def test_a_command_for_a_flight_plugin_waits_until_it_has_reported_since_arming():
    held, sent = HeldCommands(), []
    # Flown before: its counters are old. Armed again at 5 s, the table shows it running.
    table = health(True, counted_us=1_000_000)
    held.follow(table, 5_000_000)
    assert not held.listening(table, CONTROLLER)
    held.hold(CONTROLLER, 100.0, VehicleCommand(seq=7))
    held.release(table, 1.0, sent.append)
    assert sent == []
    table = health(True, counted_us=5_200_000)  # its first counters after init
    held.release(table, 1.5, sent.append)
    assert [c.seq for c in sent] == [7] and held.held == []
    assert held.listening(table, CONTROLLER)
    held.follow(health(False, 5_200_000), 9_000_000)  # disarmed: starting again next time
    assert not held.listening(health(True, 5_200_000), CONTROLLER)


def test_a_command_never_heard_is_dropped_when_its_wait_ends():
    held, sent = HeldCommands(), []
    table = health(True, counted_us=0)
    held.follow(table, 5_000_000)
    held.hold(CONTROLLER, 10.0, VehicleCommand(seq=3))
    held.release(table, 9.9, sent.append)
    assert held.held != []
    held.release(table, 10.0, sent.append)
    assert sent == [] and held.held == []


def test_a_plugin_a_config_runs_from_the_start_listens_once_it_has_reported():
    table = health(False, counted_us=0)
    table.plugins[0].group, table.plugins[0].state = b"core", int(PluginState.RUNNING)
    assert not HeldCommands().listening(table, CONTROLLER)  # started, not yet reported
    table.plugins[0].counted_us = 2_000_000
    assert HeldCommands().listening(table, CONTROLLER)  # disarmed, and not held for ever
