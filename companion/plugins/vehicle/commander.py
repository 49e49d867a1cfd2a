"""``vehicle.commander``: the flight mode, home, guided target and failsafes (group ``core``).

Takes the mode commands off ``link/commands`` (SET_MODE, MISSION_START, RTL, REPOSITION,
LOITER, SET_HOME), answers each on ``link/command_acks`` (with the reason when refused),
applies the failsafes (ground-station link, GPS, geofence; ``companion.control.failsafe``),
the pilot's mode switch and the RC and joystick failsafes (``companion.control.pilot_watch``),
the low-battery failsafe (``companion.control.battery_failsafe``), enters Return when a
mission ends on its NAV_RETURN_TO_LAUNCH (``companion.control.mission_return``), publishes
``vehicle/status`` on every change and every 0.3 s armed (1 s disarmed), and what the
operator should read on ``vehicle/statustext``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

from companion.control import commander as rules
from companion.control.battery_failsafe import BATTERY_FS_PARAMS, BatteryFailsafe
from companion.control.commander import COMMANDER_PARAMS, MIN_ALT_PARAM, Commander
from companion.control.failsafe import FAILSAFE_PARAMS, Failsafes, Situation
from companion.control.flight.landing_flight import land_start
from companion.control.flight_state import (
    FlightState,
    in_the_air,
    load_flight_state,
    save_flight_state,
)
from companion.control.ground_rules import ground_notice, standing
from companion.control.mission.fence import Fence
from companion.control.mission.mission_files import MissionStore, StoreFollower
from companion.control.mission.rally import RALLY_PARAMS, RallyPoints
from companion.control.mission.set_current import first_takeoff
from companion.control.mission_return import returning_item
from companion.control.pilot_watch import PILOT_PARAMS, PilotWatch, receiver_process
from companion.messages import (
    CommandAck,
    CommandId,
    FlightMode,
    MissionState,
    NavFlags,
    StatusText,
    VehicleCommand,
    VehicleStatus,
)
from companion.params.live import LiveParams
from companion.plugin import Plugin, PluginContext
from companion.sensors.read_pacing import ReadPacer
from mavlink_dialect import companion as d

# Resuming a flight after a restart in the air: the navigator's first solution is looked
# for 20 times a wall second.
WAIT_S = 0.05
# Disarmed no failsafe acts: waking as often as the status goes out is enough on the bench
# (an arming wakes it at once: the supervisor's health table says so as it arms).
DISARMED_WAIT_S = 1.0
# Armed, the status goes out on every third failsafe judgement (one wake-up serves both;
# a change goes out at once): the link and the controller follow it, and an armed status
# wakes them.
STATUS_PERIOD_US = 300_000
# Disarmed, a status that has not changed goes out once a second, and wakes no reader; a
# change (an ack, the mode switch, a failsafe) is sent at once, and wakes them.
DISARMED_STATUS_PERIOD_US = 1_000_000
FAILSAFE_PERIOD_US = 100_000  # failsafes are judged ten times a (vehicle) second
# A restart with an armed flight state on file waits this long (vehicle time) for the
# execution control's table and the navigator to say whether the flight is still on.
RESUME_WAIT_US = 10_000_000
REARM_WAIT_US = 5_000_000  # after asking to be armed again: the supervisor's answer, at most
REARM_SEQ = (1 << 31) - 1  # the commander's own START, apart from the link's numbers
ZONES = frozenset({d.MAV_MISSION_TYPE_FENCE, d.MAV_MISSION_TYPE_RALLY})


class CommanderPlugin(Plugin):
    """Mode state for the link and the flight controller."""

    params = (*COMMANDER_PARAMS, *FAILSAFE_PARAMS, *PILOT_PARAMS, *BATTERY_FS_PARAMS,
              *RALLY_PARAMS)  # fmt: skip
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
    outputs = ("vehicle/status", "link/command_acks", "vehicle/statustext", "link/commands")

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        state_dir = Path(ctx.vehicle.get("state_dir", "."))
        self._read_flight_state(state_dir)
        self.store = MissionStore(state_dir / "missions")
        # The link stores missions in its own process and says so on mission/changed.
        self.follower = StoreFollower(self.store)
        self.live = LiveParams(ctx.bus, self.params, state_dir)
        self.commander = Commander(
            lambda: len(self.store.items[d.MAV_MISSION_TYPE_MISSION]),
            lambda: land_start(self.store.items[d.MAV_MISSION_TYPE_MISSION]) is not None,
            lambda: self.live[MIN_ALT_PARAM],
            lambda: first_takeoff(self.store.items[d.MAV_MISSION_TYPE_MISSION]),
            self.live.values,
        )
        self._load_zones()
        self.failsafes, self.pilot = Failsafes(self.live.values), PilotWatch(self.live.values)
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
        # more, the sticks at 50 Hz) is read when it wakes on its own (``_pause``): waking
        # for every navigation sample cost a lockstep simulation a tenth of its speed.
        # The health table too: the supervisor publishes it as it arms or disarms, and a
        # disarmed commander otherwise sleeps a whole second.
        self.waiter = bus.waiter([self.commands, self.rc_switch, self.health])
        self.acks = bus.writer("link/command_acks")
        self.arm_again = bus.writer("link/commands")
        self.out = bus.writer("vehicle/status")
        self.texts = bus.writer("vehicle/statustext")
        self.next_status_us = self.next_failsafe_us = 0
        self.last_status = b""  # the last status published, time stamp left out
        self.nav_seen: Any = None  # the last solution read, usable or not
        self.nav_good: Any = None  # the last usable one
        self.arms = 0  # times armed, for the ground notice
        self.told: tuple[int, int] = (-1, -1)  # (mode changes, arms) last told about
        # Armed, it wakes when its next failsafe judgement falls due in vehicle time
        # (commands and the mode switch wake it at once): waking 20 times a wall second
        # judged nothing more often, and in a simulation running faster than real time it
        # judged the failsafes less often than their period.
        self.pace = ReadPacer(0.0)
        self.pause_s = WAIT_S

    def step(self) -> None:
        c = self.commander
        # A flight to resume is judged as often as an armed one: a restart in the air waits
        # for the navigator's first solution, not for the next second.
        self.waiter.sleep(self.pause_s)
        now = self.ctx.clock.now_us()
        self.pace.read_at(now, time.monotonic())
        nav = self._nav()
        health = self.health.get()
        if self.saved is not None and not self._resume(now, nav, health):
            return  # no status until it is known whether the flight goes on
        if health is not None and (health.flight_running or now >= self.rearm_until_us):
            self.arms += int(bool(health.flight_running) and not c.armed)
            c.on_armed(bool(health.flight_running))
        self.live.poll()
        if self.follower.follow(self.mission_changes.get()) & ZONES:
            self._load_zones()
        control = self.control.get()
        if control is not None and not control.fresh(now):
            control = None  # a stopped controller's last status says nothing now
        c.land_phase = int(control.land_phase) if control is not None else 0
        # Until the controller started at arming speaks, judged as it would judge it.
        home_alt = c.home[2] if c.home is not None else None
        landed = bool(control.landed) if control is not None else standing(nav, home_alt)
        c.landed = bool(c.armed and landed)
        acks = self._commands()
        changed = bool(acks) | self._mode_switch(now) | self._mission_return(now, control)
        self._ground_notice(now, landed is not None)
        if now >= self.next_failsafe_us or now < self.next_failsafe_us - FAILSAFE_PERIOD_US:
            self.next_failsafe_us = now + FAILSAFE_PERIOD_US
            changed |= self._failsafes(now, nav, control)
        for text in c.take_notices():  # where Return goes, after what sent it there
            self._say(now, text, d.MAV_SEVERITY_INFO)
        if changed or now >= self.next_status_us:
            self._publish_status(c.status(now), c.armed)
            self.next_status_us = now + (STATUS_PERIOD_US if c.armed else DISARMED_STATUS_PERIOD_US)
            self.ctx.health.ok()
        # After the status: whoever hears an ack finds the status already saying so (a
        # simulation held for MISSION_START's ack resumed while the controller still read
        # the old mode, when this process was preempted between the two).
        for ack in acks:
            self.acks.publish(ack)
        self._keep_flight_state(control)
        self.pause_s = self._pause(now)

    def _pause(self, now: int) -> float:
        """How long to sleep unless woken: armed, until the next failsafe judgement (the
        status, due every third one, goes out on the same wake-up)."""
        if self.saved is not None:
            return WAIT_S
        if not self.commander.armed:
            return DISARMED_WAIT_S
        wait_s = self.pace.wall_s_until(self.next_failsafe_us, now)
        return min(wait_s, FAILSAFE_PERIOD_US / 1e6)

    def _read_flight_state(self, state_dir: Path) -> None:
        self.state_dir = state_dir
        # The flight this commander's last process left (None: none, or nothing to resume).
        self.saved = load_flight_state(state_dir)
        self.resume_until_us: int | None = None
        self.rearm_until_us = 0  # asked to be armed again: armed, whatever the table says yet
        self.written = ""  # the flight state last written
        self.judged: FlightState | None = None  # the state last compared with it
        # Whether the file says armed (a start on the ground after a flight rewrites it).
        self.written_armed = self.saved is not None and self.saved.armed

    def _resume(self, now: int, nav: Any, health: Any) -> bool:
        """Carry on the flight the last process left, if it is still on; False: not known yet.

        Still armed by the execution control (only this process restarted), or in the air
        by the navigator's judgement (everything restarted): the mode, home, target and
        mission item come back, and the aircraft is armed again if it must be. On the
        ground, or when nothing says so in time, it starts disarmed as after any start.
        """
        saved = self.saved
        assert saved is not None
        if self.resume_until_us is None:
            self.resume_until_us = now + RESUME_WAIT_US
        armed = health is not None and bool(health.flight_running)
        flying = in_the_air(nav, saved.home)
        if saved.armed and (armed or flying):
            self.saved = None
            self.commander.restore(saved)
            if not armed:
                self._arm_again(now)
            mode = FlightMode(saved.mode)
            item = f" at item {saved.mission_seq}" if mode == FlightMode.MISSION else ""
            text = f"Restarted in flight: {mode.name.title()} resumed{item}"
            self.ctx.log.warning("%s", text)
            self._say(now, text, d.MAV_SEVERITY_WARNING)
            return True
        judged = health is not None and nav is not None and nav.flags & NavFlags.POSITION_VALID
        if not saved.armed or judged or now >= self.resume_until_us:
            self.saved = None
            return True
        return False

    def _arm_again(self, now: int) -> None:
        """Ask the execution control to start the flight plug-ins, without pre-arm checks
        (the aircraft is flying: a check that fails now must not drop it)."""
        self.arm_again.publish(
            VehicleCommand(t_us=now, seq=REARM_SEQ, command=CommandId.START, source_sysid=0)
        )
        self.rearm_until_us = now + REARM_WAIT_US

    def _keep_flight_state(self, control: Any) -> None:
        """Write the flight state when it changed (the mission's item, from the controller)."""
        c = self.commander
        flying_mission = c.armed and c.mode == FlightMode.MISSION
        # A controller with no mission running (restarted, its first steps refused) says
        # item 0: the item to resume from is still the one saved.
        if (
            flying_mission
            and control is not None
            and control.mission_state != MissionState.NOT_STARTED
        ):
            c.mission_first = max(0, int(control.mission_seq))
        state = c.snapshot()
        # The same state as last step (nearly every step): the same verdict, without the
        # JSON it would be judged by (a NaN field only makes the two unequal).
        if state == self.judged:
            return
        self.judged = state
        text = state.to_json()
        # Disarmed, the file changes only to say a flight has ended: a vehicle on the bench
        # writes nothing to its state directory (nothing to resume from there).
        if text != self.written and (state.armed or self.written_armed):
            save_flight_state(self.state_dir, state)
            self.written, self.written_armed = text, state.armed

    def _load_zones(self) -> None:
        """The fence, and the rally points Return may fly to inside it."""
        items = self.store.items
        self.fence = Fence.from_items(items[d.MAV_MISSION_TYPE_FENCE])
        rally = RallyPoints.from_items(items[d.MAV_MISSION_TYPE_RALLY], self.fence)
        self.commander.rally = rally

    def _ground_notice(self, now: int, known: bool) -> None:
        """Armed on the ground, say once per arming and per mode entered what the aircraft
        will do from there (``companion.control.ground_rules``): never armed and silent.
        A mode entered in the air is not told of when the aircraft lands in it."""
        c = self.commander
        key = (c.changes, self.arms)
        if not (c.armed and known) or key == self.told:
            return
        self.told = key
        if not c.landed:
            return
        items = self.store.items[d.MAV_MISSION_TYPE_MISSION]
        text = ground_notice(c.mode, items, c.mission_first)
        if text is not None:
            self.ctx.log.info("%s", text)
            self._say(now, text, d.MAV_SEVERITY_NOTICE)

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
            if cmd.command not in rules.MODE_COMMANDS:
                continue  # START, STOP, restarts: the execution control's
            decision = self.commander.handle(cmd)
            if decision is None:
                continue
            source, now = self.ctx.name.encode(), self.ctx.clock.now_us()
            acks.append(CommandAck.answer(cmd, now, source, decision.result, decision.reason))
            if decision.result == 0 and cmd.command in rules.MODE_CHOICES:
                self.failsafes.operator_chose(self.commander.mode)
            if decision.reason:
                self.ctx.log.info("refused: %s", decision.reason)
        return acks

    def _failsafes(self, now: int, nav: Any, control: Any) -> bool:
        c = self.commander
        flying = c.armed and control is not None and not control.landed  # control: fresh
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
            receiver = receiver_process(self.health.get())
            actions += self.pilot.step(int(nav.t_us), c.mode, bool(flying), rc, joystick, receiver)
        return self._act(now, actions)

    def _mission_return(self, now: int, control: Any) -> bool:
        c, items = self.commander, self.store.items[d.MAV_MISSION_TYPE_MISSION]
        seq = returning_item(items, control, c.mode, c.changes, c.landed)
        if seq is None or c.failsafe(FlightMode.RTL).result != 0:
            return False
        self._say(now, f"Mission: item {seq} returns to launch", d.MAV_SEVERITY_INFO)
        return True

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
            if decision.result == 0:
                self.failsafes.operator_chose(mode)
                changed = True
        return changed

    def _say(self, now: int, text: str, severity: int) -> None:
        self.texts.publish(StatusText.of(now, severity, text))

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
