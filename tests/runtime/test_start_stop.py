"""START runs the flight group, STOP stops it; the core group keeps running throughout."""

from __future__ import annotations

from companion.messages import CommandId, CommandResult, PluginState, VehicleCommand
from tests.support.configs import pipeline
from tests.support.vehicle import wait_for


def send(vehicle, command: CommandId, seq: int) -> None:
    vehicle.commands.publish(VehicleCommand(t_us=0, seq=seq, command=int(command)))


def ack_for(vehicle, seq: int):
    for ack in vehicle.acks.take():
        vehicle.seen_acks[ack.seq] = ack
    return vehicle.seen_acks.get(seq)


def test_start_and_stop_toggle_only_the_flight_group(vehicle_factory):
    vehicle = vehicle_factory(pipeline(relay_group="flight"))
    vehicle.commands = vehicle.bus.writer("link/commands")
    vehicle.acks = vehicle.bus.queue_reader("link/command_acks")
    vehicle.seen_acks = {}
    nav = vehicle.bus.latest_reader("nav/state")
    core_pids = (vehicle.wait_running("imu"), vehicle.wait_running("idle"))
    assert vehicle.row("relay").state == PluginState.STOPPED
    assert nav.wait(0.5) is None, "nothing flies before START"

    send(vehicle, CommandId.START, 1)
    ack = wait_for(lambda: ack_for(vehicle, 1), 5, "START acknowledged")
    assert ack.result == CommandResult.ACCEPTED
    wait_for(lambda: vehicle.row("relay").state == PluginState.RUNNING, 5, "relay running")
    assert vehicle.health().flight_running == 1
    assert wait_for(lambda: nav.wait(0.2), 5, "nav/state from the flight group")

    send(vehicle, CommandId.STOP, 2)
    assert wait_for(lambda: ack_for(vehicle, 2), 5, "STOP acknowledged").result == 0
    wait_for(lambda: vehicle.row("relay").state == PluginState.STOPPED, 5, "relay stopped")
    assert vehicle.row("relay").pid == 0
    assert vehicle.health().flight_running == 0
    assert (vehicle.row("imu").pid, vehicle.row("idle").pid) == core_pids
    assert vehicle.row("imu").restarts == 0

    send(vehicle, CommandId.START, 3)
    wait_for(lambda: vehicle.row("relay").state == PluginState.RUNNING, 5, "relay again")
