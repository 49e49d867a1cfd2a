"""DO_PAUSE_CONTINUE as ArduPlane takes it: pause holds where the aircraft is (what
QGroundControl's Pause does), continue flies the mission on from the item it was left at;
each refused with the reason where it means nothing. The commands the link publishes are
handed to a real Commander, which decides the mode."""

from __future__ import annotations

import math

import pytest
from pymavlink.dialects.v20 import common as m

from companion.control.commander import Commander
from companion.control.mission.items import MissionItem
from companion.control.mission.mission_files import MissionStore
from companion.link.codec import new_encoder
from companion.link.command_rules import RULES, refusal
from companion.link.command_service import CommandArgs, CommandService
from companion.link.commands import MissionCommands
from companion.link.microservice import Peer
from companion.link.mission_service import MissionService
from companion.messages import CommandResult, ControlStatus, FlightMode, VehicleCommand
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)


class Bench:
    def __init__(self) -> None:
        mav = new_encoder(1, 1)
        self.service = CommandService(mav, 1, 1)
        self.service.guard(refusal, RULES)
        self.vehicle = RecordingVehicle()
        self.service.on_refusal = self.vehicle.statustext
        self.missions = MissionService(mav, MissionStore(None), 1, 1)
        waypoint = MissionItem(0, 3, m.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0, 0, 0, 50.0)
        self.missions.store.replace(0, [waypoint] * 3)
        MissionCommands(self.vehicle, self.missions).register(self.service)
        self.commander = Commander(lambda: 3)
        self.commander.position = (-37.9, 145.1, 200.0)
        self.commander.home = (-37.9, 145.1, 100.0)
        self.commander.on_armed(True)

    def fly(self, mode: FlightMode) -> None:
        """In the air in ``mode``, as the controller and the commander say."""
        self.commander.failsafe(mode)
        self.vehicle.snapshot.control = ControlStatus(landed=0)
        self.vehicle.snapshot.status = self.commander.status(0)

    def send(self, *params: float) -> int:
        """The result: the link's own, or the commander's for what the link passed on."""
        full = (*params, *[0.0] * (7 - len(params)))
        args = CommandArgs(m.MAV_CMD_DO_PAUSE_CONTINUE, full, 0, GCS)
        published = len(self.vehicle.published)
        out = self.service.dispatch(args, 0.0)
        if out:
            return out[0].msg.result
        command, values = self.vehicle.published[published]
        cmd = VehicleCommand(command=command)
        for i, v in enumerate(values):
            cmd.param[i] = v
        decision = self.commander.handle(cmd)
        assert decision is not None
        self.vehicle.snapshot.status = self.commander.status(0)
        return int(decision.result)


def test_pause_holds_the_mission_and_continue_flies_it_on():
    bench = Bench()
    bench.fly(FlightMode.MISSION)
    bench.missions.follow(3, 2)  # the controller flies item 2: MISSION_STATE_ACTIVE
    assert bench.send(0) == CommandResult.ACCEPTED
    assert bench.commander.mode == FlightMode.LOITER  # circling where it is
    bench.vehicle.snapshot.mission_paused = bench.missions.paused
    assert bench.send(1) == CommandResult.ACCEPTED
    assert bench.commander.mode == FlightMode.MISSION
    assert bench.missions.current == 2  # on from the item it was left at
    assert bench.send(1) == CommandResult.ACCEPTED  # flying it already: nothing to do
    assert bench.vehicle.texts == []


def test_on_the_ground_or_without_a_mission_left_it_is_refused_with_the_reason():
    bench = Bench()
    bench.vehicle.snapshot.control = ControlStatus(landed=1)
    assert bench.send(0) == m.MAV_RESULT_DENIED
    assert bench.vehicle.texts[-1] == "Pause: not flying"
    bench.fly(FlightMode.GUIDED)
    assert bench.send(1) == m.MAV_RESULT_DENIED
    assert bench.vehicle.texts[-1] == "Continue: no mission left to continue"
    assert bench.commander.mode == FlightMode.GUIDED and bench.service.refused == 2


@pytest.mark.parametrize("bad", [math.nan, math.inf, 2, -1, 0.5])
def test_hostile_parameters_are_denied_counted_and_said(bad):
    bench = Bench()
    bench.fly(FlightMode.MISSION)
    assert bench.send(bad) == m.MAV_RESULT_DENIED
    assert bench.service.refused == 1 and bench.vehicle.published == []
    assert bench.vehicle.texts[0].startswith("DO_PAUSE_CONTINUE: param1 (continue)")
    assert bench.commander.mode == FlightMode.MISSION
