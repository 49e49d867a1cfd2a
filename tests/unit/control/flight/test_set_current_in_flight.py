"""MISSION_SET_CURRENT flown: a mission running goes to the item set at once.

square.plan is flown from the airborne start by the point-mass aircraft of
``test_restart_in_flight``. The commander's status is fed back as the plug-in makes it:
``mission_first`` overwritten each step by the item the controller said last (that report
lags), and the set-current told as a count and an item (``mission_jumps``,
``mission_jump_to``). Before the controller acted on it, the aircraft flew on to item 1,
then 2, whatever item was set.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from companion.control.flight.controller import FlightController
from companion.geodesy import STANDARD_GRAVITY as G
from companion.messages import FlightMode
from tests.unit.control.flight.test_restart_in_flight import (
    DT,
    ITEMS,
    _controller,
    _nav,
    _place,
    _status,
)


@dataclass
class Commander:
    """What the commander plug-in tells the controller (the part these tests change)."""

    mode: FlightMode = FlightMode.MISSION
    changes: int = 1
    jumps: int = 0
    jump_to: int = -1
    first: int = 0  # overwritten with the controller's last report, a step late

    def status(self):
        s = _status(self.first)
        s.mode, s.changes = int(self.mode), self.changes
        s.mission_jumps, s.mission_jump_to = self.jumps, self.jump_to
        return s


@dataclass
class Flight:
    track: list[tuple[float, float]] = field(default_factory=list)
    seqs: list[int] = field(default_factory=list)
    reached: list[int] = field(default_factory=list)


def _fly(duration_s: float, event) -> Flight:
    """Fly ``duration_s``; ``event(i, pos, out, commander)`` may change what the commander
    says, or return a new controller (the old one's process restarted)."""
    controller: FlightController = _controller()
    cmd, flight = Commander(), Flight()
    v = controller.config["AIRSPEED_CRUISE"]
    pos, course, roll = (0.0, 0.0), math.pi / 2, 0.0
    for i in range(round(duration_s / DT)):
        t = i * DT
        out = controller.step(_nav(t, pos, course, roll, v), cmd.status(), t)
        cmd.first = out.mission_seq  # the plug-in's overwrite, seen by the next step
        flight.seqs.append(out.mission_seq)
        flight.reached += out.reached
        replaced = event(i, pos, out, cmd)
        controller = replaced if replaced is not None else controller
        roll = out.nav_roll
        course += G * math.tan(roll) / v * DT
        pos = (pos[0] + v * math.cos(course) * DT, pos[1] + v * math.sin(course) * DT)
        flight.track.append(pos)
    return flight


def _first_near(flight: Flight, seq: int, after: int = 0) -> int | None:
    """The first step from ``after`` at which the track is within item ``seq``'s
    acceptance radius (None: never)."""
    radius = ITEMS[seq].acceptance_m(30.0)
    b = _place(seq)
    return next(
        (i for i, p in enumerate(flight.track) if i >= after and math.dist(p, b) <= radius), None
    )


AT = round(30.0 / DT)  # 30 s in: on the leg to item 1


def _set_current_to_3(i, pos, out, cmd):
    if i == AT:
        assert out.mission_seq == 1
        cmd.jumps, cmd.jump_to = cmd.jumps + 1, 3


def test_a_set_current_while_flying_to_item_1_flies_to_item_3_at_once():
    flight = _fly(150.0, _set_current_to_3)
    assert flight.seqs[AT + 1] == 3  # MISSION_CURRENT says it from the next step
    at3 = _first_near(flight, 3, AT)
    assert at3 is not None, "never reached item 3"
    at2 = _first_near(flight, 2, AT)
    assert at2 is None or at2 > at3, "flew to item 2 first"
    assert _first_near(flight, 1, AT) is None  # nor on to the item it was flying to
    assert 1 not in flight.reached and 2 not in flight.reached  # skipped: never "reached"
    assert 3 in flight.reached
    assert flight.seqs[at3 + 1] == 4  # and on to the item after it


def test_an_unrelated_re_entry_of_mission_keeps_the_item_flown():
    """Mission entered again (a second SET_MODE Mission: ``changes`` grows) while the report
    the commander holds lags an item behind: the mission goes on to its own item."""
    at_item_2 = []

    def re_enter(i, pos, out, cmd):
        _set_current_to_3(i, pos, out, cmd)  # a jump before: its count stays as it was
        if out.mission_seq == 4 and not at_item_2:
            at_item_2.append(i)
            cmd.changes += 1
            cmd.first = 3  # the lagging report

    flight = _fly(150.0, re_enter)
    assert at_item_2, "never flew to item 4"
    i = at_item_2[0]
    assert flight.seqs[i + 1 :][:50] == [4] * 50


def test_a_set_current_in_another_mode_is_where_the_mission_goes_on_from():
    def loiter_then_mission(i, pos, out, cmd):
        if i == AT:
            cmd.mode, cmd.changes = FlightMode.LOITER, cmd.changes + 1
        if i == AT + 100:
            cmd.jumps, cmd.jump_to = 1, 3
        if i == AT + 200:
            cmd.mode, cmd.changes = FlightMode.MISSION, cmd.changes + 1
            cmd.first = 1  # the commander's overwrite, stale: the controller said 1 last

    flight = _fly(60.0, loiter_then_mission)
    assert flight.seqs[AT + 201] == 3


def test_a_restarted_controller_does_not_take_the_count_it_sees_first_for_a_jump():
    def restart(i, pos, out, cmd):
        if i == AT - 200:  # an earlier set-current, to item 1 (flown to since)
            cmd.jumps, cmd.jump_to = 1, 1
        if i == AT:
            assert out.mission_seq == 1
            cmd.jump_to = 3  # (as if the count were older than this controller)
            return _controller()
        return None

    flight = _fly(40.0, restart)
    assert set(flight.seqs[AT + 1 :]) == {1}


def test_a_restarted_commander_does_not_jump_and_its_next_set_current_does():
    def restart(i, pos, out, cmd):
        if i == AT - 100:
            cmd.jumps, cmd.jump_to = 2, 1  # set-currents before (to the item flown)
        if i == AT:
            cmd.jumps, cmd.jump_to = 2, 3  # restored from its state: the same count
        if i == AT + 50:
            cmd.jumps, cmd.jump_to = 0, 3  # an older state file: no count at all
        if i == AT + 100:
            cmd.jumps, cmd.jump_to = 1, 3  # its first set-current after the restart

    flight = _fly(40.0, restart)
    assert set(flight.seqs[AT - 99 : AT + 101]) == {1}
    assert flight.seqs[AT + 101] == 3
