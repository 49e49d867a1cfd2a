"""``vehicle.commander``: the flight mode, home, guided target and failsafes (group ``core``).

Takes the mode commands off ``link/commands`` (SET_MODE, MISSION_START, RTL, REPOSITION,
LOITER, SET_HOME), answers each on ``link/command_acks`` (with the reason when refused),
applies the failsafes (ground-station link, GPS, geofence; ``companion.control.failsafe``),
the pilot's mode switch and the RC and joystick failsafes (``companion.control.pilot_watch``), the
low-battery failsafe (``companion.control.battery_failsafe``), and
publishes ``vehicle/status`` on every change and four times a second, and what the
operator should read on ``vehicle/statustext``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from companion.control.battery_failsafe import BATTERY_FS_PARAMS, BatteryFailsafe
from companion.control.commander import COMMANDER_PARAMS, MIN_ALT_PARAM, MODE_COMMANDS, Commander
from companion.control.failsafe import FAILSAFE_PARAMS, Failsafes, Situation
from companion.control.flight.landing_flight import land_start
from companion.control.mission.fence import Fence
from companion.control.mission.store import MissionStore, StoreFollower
from companion.control.pilot_watch import PILOT_PARAMS, PilotWatch
from companion.messages import (
    NAME_LEN,
    REASON_LEN,
    CommandAck,
    FlightMode,
    NavFlags,
    StatusText,
    VehicleStatus,
)
from companion.params.live import LiveParams
from companion.plugin import Plugin, PluginContext
from mavlink_dialect import companion as d

WAIT_S = 0.05  # armed: navigation, sticks and failsafes looked at 20 times a wall second
# Disarmed no failsafe acts: waking as often as the status goes out is enough on the bench
# (an arming wakes it at once: the supervisor's health table says so as it arms).
DISARMED_WAIT_S = 1.0
STATUS_PERIOD_US = 250_000  # 4 Hz: the link and the controller follow it
# Disarmed, a status that has not changed goes out once a second, and wakes no reader; a
# change (an ack, the mode switch, a failsafe) is sent at once, and wakes them.
DISARMED_STATUS_PERIOD_US = 1_000_000
FAILSAFE_PERIOD_US = 100_000  # failsafes are judged ten times a (vehicle) second


class CommanderPlugin(Plugin):
    """Mode state for the link and the flight controller."""

    params = (*COMMANDER_PARAMS, *FAILSAFE_PARAMS, *PILOT_PARAMS, *BATTERY_FS_PARAMS)
    inputs = ("link/commands",)
    optional_inputs = (
        "nav/state",
        "system/health",
        "control/status",
        "link/status",
        "mission/changed",
        "sensors/rc",
        "sensors/rc_switch",
        "link/manual_control",
        "sensors/battery",
    )
    outputs = ("vehicle/status", "link/command_acks", "vehicle/statustext")

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        state_dir = Path(ctx.vehicle.get("state_dir", "."))
        self.store = MissionStore(state_dir / "missions")
        self.fence = Fence.from_items(self.store.items[d.MAV_MISSION_TYPE_FENCE])
        # The link stores missions in its own process and says so on mission/changed.
        self.follower = StoreFollower(self.store)
        self.live = LiveParams(ctx.bus, self.params, state_dir)
        self.commander = Commander(
            lambda: len(self.store.items[d.MAV_MISSION_TYPE_MISSION]),
            lambda: land_start(self.store.items[d.MAV_MISSION_TYPE_MISSION]) is not None,
            lambda: self.live[MIN_ALT_PARAM],
        )
        self.failsafes = Failsafes(self.live.values)
        self.pilot = PilotWatch(self.live.values)
        self.battery_failsafe = BatteryFailsafe(self.live.values)
        bus = ctx.bus
        self.commands = bus.queue_reader("link/commands")
        self.nav = bus.latest_reader("nav/state")
        self.health = bus.latest_reader("system/health")
        self.control = bus.latest_reader("control/status")
        self.link = bus.latest_reader("link/status")
        self.mission_changes = bus.latest_reader("mission/changed")
        self.battery = bus.latest_reader("sensors/battery")
        self.rc = bus.latest_reader("sensors/rc")
        self.rc_switch = bus.queue_reader("sensors/rc_switch")
        self.joystick = bus.latest_reader("link/manual_control")
        # Commands and the mode switch wake it at once; the rest (navigation at 100 Hz and
        # more, the sticks at 50 Hz) is read when it wakes on its own (``WAIT_S``): waking
        # for every navigation sample cost a lockstep simulation a tenth of its speed.
        # The health table too: the supervisor publishes it as it arms or disarms, and a
        # disarmed commander otherwise sleeps a whole second.
        self.waiter = bus.waiter([self.commands, self.rc_switch, self.health])
        self.acks = bus.writer("link/command_acks")
        self.out = bus.writer("vehicle/status")
        self.texts = bus.writer("vehicle/statustext")
        self.next_status_us = 0
        self.last_status = b""  # the last status published, time stamp left out
        self.next_failsafe_us = 0
        self.nav_seen: Any = None  # the last solution read, usable or not
        self.nav_good: Any = None  # the last usable one

    def step(self) -> None:
        c = self.commander
        self.waiter.wait(WAIT_S if c.armed else DISARMED_WAIT_S)
        now = self.ctx.clock.now_us()
        nav = self._nav()
        if (health := self.health.get()) is not None:
            c.on_armed(bool(health.flight_running))
        self.live.poll()
        if d.MAV_MISSION_TYPE_FENCE in self.follower.follow(self.mission_changes.get()):
            self.fence = Fence.from_items(self.store.items[d.MAV_MISSION_TYPE_FENCE])
        if (control := self.control.get()) is not None:
            c.land_phase = int(control.land_phase) if control.fresh(now) else 0
        acks = self._commands()
        changed = bool(acks) | self._mode_switch(now)
        if now >= self.next_failsafe_us or now < self.next_failsafe_us - FAILSAFE_PERIOD_US:
            self.next_failsafe_us = now + FAILSAFE_PERIOD_US
            changed |= self._failsafes(now, nav)
        if changed or now >= self.next_status_us:
            self._publish_status(c.status(now), c.armed)
            self.next_status_us = now + (STATUS_PERIOD_US if c.armed else DISARMED_STATUS_PERIOD_US)
            self.ctx.health.ok()
        # After the status: whoever hears an ack finds the status already saying so (a
        # simulation held for MISSION_START's ack resumed while the controller still read
        # the old mode, when this process was preempted between the two).
        for ack in acks:
            self.acks.publish(ack)

    def _publish_status(self, status: VehicleStatus, armed: bool) -> None:
        """Disarmed, the same status again wakes nobody (the link would wake for it each
        second); armed, the controller started with the flight may be waiting for it."""
        content = bytes(status)[VehicleStatus.mode.offset :]  # all but the time stamp
        self.out.publish(status, wake=armed or content != self.last_status)
        self.last_status = content

    def _nav(self) -> Any:
        """The newest usable navigation solution: one whose position is not a place is
        counted and ignored (not home, not judged by the failsafes), as if never sent."""
        nav = self.nav.get()
        if nav is None or nav is self.nav_seen:
            return self.nav_good
        self.nav_seen = nav
        if self.commander.on_nav(nav):
            self.nav_good = nav
        else:
            if self.ctx.health.refused == 0:
                self.ctx.log.warning("navigation position not a place: ignored (counted)")
            self.ctx.health.refused += 1
        return self.nav_good

    def _commands(self) -> list[CommandAck]:
        """The mode commands handled, as their acks (published after the new status)."""
        acks = []
        for cmd in self.commands.drain():
            if cmd.command not in MODE_COMMANDS:
                continue  # START, STOP, restarts: the execution control's
            decision = self.commander.handle(cmd)
            if decision is None:
                continue
            ack = CommandAck(t_us=self.ctx.clock.now_us(), seq=cmd.seq, command=cmd.command)
            ack.result = int(decision.result)
            ack.source = self.ctx.name.encode()[: NAME_LEN - 1]
            ack.reason = decision.reason.encode()[:REASON_LEN]
            acks.append(ack)
            if decision.reason:
                self.ctx.log.info("refused: %s", decision.reason)
        return acks

    def _failsafes(self, now: int, nav: Any) -> bool:
        c = self.commander
        control = self.control.get()
        flying = c.armed and control is not None and control.fresh(now) and not control.landed
        link = self.link.get()
        valid = nav is not None and nav.flags & NavFlags.POSITION_VALID
        situation = Situation(
            now_us=now,
            mode=c.mode,
            flying=bool(flying),
            gcs_silence_s=link.gcs_silence_s if link is not None else math.nan,
            nav_flags=nav.flags if nav is not None else 0,
            nav_t_us=int(nav.t_us) if nav is not None else None,
            fence_breach=self.fence.breach(nav.lat_deg, nav.lon_deg) if valid else None,
        )
        battery = self.battery.get()
        level = int(battery.level) if battery is not None else None
        actions = self.failsafes.step(situation) + self.battery_failsafe.step(level, bool(flying))
        if nav is not None:  # the pilot's inputs are judged against the sensors' time
            rc, joystick = self.rc.get(), self.joystick.get()
            actions += self.pilot.step(int(nav.t_us), c.mode, bool(flying), rc, joystick)
        return self._act(now, actions)

    def _mode_switch(self, now: int) -> bool:
        """The pilot's switch wins over the ground station each time it moves."""
        changed = False
        for frame in self.rc_switch.drain():
            mode = self.pilot.switch_mode(frame.mode_switch)
            if mode is None or mode == self.commander.mode:
                continue
            decision = self.commander.failsafe(mode)
            name = mode.name.title()
            text = f"Mode switch: {name}" if decision.result == 0 else decision.reason
            self._say(now, text, d.MAV_SEVERITY_INFO)
            changed |= decision.result == 0
        return changed

    def _say(self, now: int, text: str, severity: int) -> None:
        msg = StatusText(t_us=now, severity=severity)
        msg.text = text.encode()[:199]
        self.texts.publish(msg)

    def _act(self, now: int, actions: list[Any]) -> bool:
        c = self.commander
        changed = False
        for action in actions:
            self.ctx.log.warning("%s", action.text)
            self._say(now, action.text, action.severity)
            if action.mode is not None and action.mode != c.mode:
                changed |= c.failsafe(FlightMode(action.mode)).result == 0
        return changed

    def close(self) -> None:
        self.waiter.close()
