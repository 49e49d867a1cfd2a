"""``control.fixed_wing``: flies the modes and the stored mission (group ``flight``).

Runs on every navigation solution: the commander's mode and targets (and, for Manual and
Stabilized, the pilot's sticks from the receiver or the ground station's joystick) in,
normalised surface commands out on ``control/actuators`` (the servo plug-in turns them
into bytes),
and guidance and mission progress on ``control/status`` for the link. Every gain, limit
and speed is a parameter: the airframe file gives the defaults, the ground station may
change them in flight (they arrive on ``params/changes``). A landing flares on the
rangefinder's height (``sensors/range``) when it has a usable one (``range_height.py``).
"""

from __future__ import annotations

import ctypes
import math
import struct
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

from companion.actuators.airframe import AirframeError, load_airframe
from companion.control.flight.attitude_modes import pilot_sticks
from companion.control.flight.controller import ControlOutput, FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.actuator_sets import ACTUATOR_PARAMS, ActuatorSets
from companion.control.mission.camera import CAMERA_PARAMS
from companion.control.mission.camera_shots import CameraPorts, CameraShots
from companion.control.mission.fence import Fence
from companion.control.mission.gripper import GRIPPER_PARAMS, Gripper
from companion.control.mission.home_items import set_home_command
from companion.control.mission.items import MissionItem
from companion.control.mission.jump_counts import JumpCounts
from companion.control.mission.mission_files import MissionStore, StoreFollower
from companion.control.mission.servo_payload import configure_payloads
from companion.control.mission_return import reported_state
from companion.messages import (
    MISSION_SERVO_SEQ,
    ActuatorCommand,
    CommandAck,
    CommandId,
    CommandResult,
    ControlStatus,
    FlightMode,
    StatusText,
    TakeoffPhase,
    VehicleCommand,
    VehicleStatus,
)
from companion.params import ParamDecl
from companion.params.live import LiveParams
from companion.plugin import FLIGHT_NICE, NO_VEHICLE, Plugin, PluginContext, Setting
from mavlink_dialect import companion as d

WAIT_S = 0.5
STATUS_WAIT_S = 5.0  # the commander's last status, once, when this process starts
OUTPUT_WAIT_S = 5.0  # ... and the servo output's process, started with this one, listening
STATUS_PERIOD_US = 100_000  # control/status at 10 Hz (and at once when an item is reached)
FENCE = d.MAV_MISSION_TYPE_FENCE
RECENT = 4  # receiver and rangefinder values kept between steps (100 Hz against 50 Hz)
# The command made in one call from its packed fields (its native layout: t_us, the four
# surfaces, aux[4], armed, padding), not field by field through ctypes, at every step.
_COMMAND_PACK = struct.Struct("=q8dB7x")
assert _COMMAND_PACK.size == ctypes.sizeof(ActuatorCommand)


class FixedWingPlugin(Plugin):
    """Guidance, energy and attitude control for one airframe."""

    nice = FLIGHT_NICE
    trigger = "nav/state"
    trigger_timeout_s = WAIT_S

    # The airframe (gains, limits, speeds as parameter defaults) is the vehicle's:
    # [vehicle] airframe, the same file the servo output and the flight log read.
    settings: ClassVar[dict[str, Setting]] = {}
    inputs = ("nav/state",)
    optional_inputs = (
        "vehicle/status",
        "params/changes",
        "mission/changed",
        "sensors/rc",
        "link/manual_control",
        "actuators/servos",
        "sensors/range",
        "sensors/gps",
        "link/commands",
    )
    outputs = (
        "control/actuators",
        "control/status",
        "link/commands",
        "vehicle/statustext",
        "camera/capture",
        "link/command_acks",
    )

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """The airframe's [control] table must name only the controller's parameters."""
        try:
            control_params(load_airframe(vehicle["airframe"]).control)
        except (AirframeError, KeyError) as exc:
            return [f"airframe: {exc}"]
        return []

    @classmethod
    def param_decls(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> tuple[ParamDecl, ...]:
        airframe = load_airframe(vehicle["airframe"])
        control = control_params(airframe.control, f"airframe {Path(airframe.source).name}")
        return control + CAMERA_PARAMS + GRIPPER_PARAMS + ACTUATOR_PARAMS

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        decls = self.param_decls(ctx.settings, ctx.vehicle)
        state_dir = Path(ctx.vehicle.get("state_dir", "."))
        # Not self.params: that is the class's declarations (Plugin.params).
        self.live_params = LiveParams(ctx.bus, decls, state_dir)
        self.missions = MissionStore(state_dir / "missions")
        self.follower = StoreFollower(self.missions)
        self.controller = FlightController(
            flight_config(self.live_params.values), self.missions.items[0]
        )
        self.controller.jumps = JumpCounts(state_dir)
        # Outputs (numbered from 1, as DO_SET_SERVO numbers them) a mission may not set.
        channels = load_airframe(ctx.vehicle["airframe"]).channels
        self.surface_outputs = {c.servo + 1: c.surface for c in channels}
        # The geofence the landing pattern Land builds keeps inside (landing_pattern.py).
        self.controller.lander.fence = Fence.from_items(self.missions.items[FENCE])
        bus = ctx.bus
        self.nav = bus.latest_reader("nav/state")
        self.status_in = bus.latest_reader("vehicle/status")
        self.mission_changes = bus.latest_reader("mission/changed")
        self.rc = bus.latest_reader("sensors/rc", keep=RECENT)
        self.joystick = bus.latest_reader("link/manual_control")
        self.range = bus.latest_reader("sensors/range", keep=RECENT)
        self.range_said = False  # the log says once when a landing flies on the range
        self.surfaces = bus.writer("control/actuators")
        self.servo_answers = bus.latest_reader("actuators/servos")
        self.output_waited = False
        self.status_out = bus.writer("control/status")
        # Landed and stopped: the controller disarms as a pilot would (execution control
        # stops the flight group, servos safe).
        self.commands = bus.writer("link/commands")
        self.texts = bus.writer("vehicle/statustext")
        self.disarm_sent = False
        self.refusing = False  # the last step's inputs were not usable
        self.reached_count = 0
        self.last_reached = -1
        self.recent_reached = [-1] * ControlStatus.REACHED_KEPT
        self.next_status_us = 0
        self.default_status = VehicleStatus(mode=int(FlightMode.LOITER), armed=1)
        gps = bus.newest_reader("sensors/gps")  # its UTC stamps the photos
        photos = CameraPorts(bus.writer("camera/capture").publish, self.commands.publish,
                             self._tell, gps.get, self._home_alt)  # fmt: skip
        self.camera = CameraShots(photos, self.surface_outputs)
        self.gripper = Gripper(self.commands.publish, self._tell, self.surface_outputs)
        self.actuators = ActuatorSets(self.commands.publish, self._tell, self.surface_outputs)
        self.requests = bus.queue_reader("link/commands")  # a ground station's payload's
        self.acks = bus.writer("link/command_acks")
        self._configure_payloads()

    def _follow_changes(self, now_us: int) -> None:
        if self.live_params.poll():
            self.controller.set_config(flight_config(self.live_params.values))
            self._configure_payloads()
        # Only a different mission restarts it: the same list stored again changes nothing.
        changed = self.follower.follow(self.mission_changes.get())
        if d.MAV_MISSION_TYPE_MISSION in changed:
            self.controller.set_mission(self.missions.items[d.MAV_MISSION_TYPE_MISSION])
            self.ctx.log.info("new mission: %d items", len(self.missions.items[0]))
        if FENCE in changed:
            self.controller.lander.fence = Fence.from_items(self.missions.items[FENCE])

    def step(self) -> None:
        nav = self.nav.wait(WAIT_S)
        if nav is None:  # the servo plug-in goes safe when commands stop
            # A payload command needs no solution: answered now, not when the first one
            # comes (just after START, in lockstep, some seconds on a loaded machine).
            self._answer_payloads(self.ctx.clock.now_us())
            return
        now_us = self.ctx.clock.now_us()
        self._follow_changes(now_us)
        # Started by START, this process joined after the commander last spoke: its mode
        # (Take-off, say) is waited for, not guessed, or the first commands would depend on
        # which process the scheduler ran first. Without a commander: loiter, armed.
        status = self.status_in.first(STATUS_WAIT_S) or self.default_status
        self._await_output()
        # The receiver first: a safety pilot's sticks win over the ground station's joystick.
        # Its frame and the rangefinder's reading are the newest measured before this
        # solution: one of the same instant may or may not have come yet (exact lockstep
        # waits for the earlier ones), and the flight must not depend on which.
        sticks = pilot_sticks(nav.t_us, self.rc.before(nav.t_us), self.joystick.get())
        rejected = self.controller.rejected
        self.controller.lander.range_reading = self.range.before(nav.t_us)
        out = self.controller.step(nav, status, nav.t_us / 1e6, sticks)
        if self.controller.lander.range_steps and not self.range_said:
            self.ctx.log.info("landing: flaring on the rangefinder's height")
            self.range_said = True
        self._count(self.controller.rejected > rejected, nav.t_us)
        self._say(now_us)
        surfaces = (out.aileron, out.elevator, out.rudder, out.throttle)
        aux = (out.flaps, out.brakes, math.nan, math.nan)  # the others not driven
        packed = _COMMAND_PACK.pack(nav.t_us, *surfaces, *aux, 1)  # armed
        self.surfaces.publish(ActuatorCommand.from_buffer_copy(packed))
        if out.disarm and not self.disarm_sent:
            self._disarm(now_us, out, status)
        self._set_servos(now_us, out.servo_sets)
        self._answer_payloads(nav.t_us)
        if out.passed_items:
            self.gripper.items(nav.t_us, out.passed_items)
            self.actuators.items(nav.t_us, out.passed_items)
            self._set_home(nav.t_us, out.passed_items)
        frame = self.controller.frame  # an idle camera costs the step nothing
        if frame is not None and (out.passed_items or self.camera.trigger.busy):
            self.camera.step(nav, out.passed_items, frame.ne(nav.lat_deg, nav.lon_deg))
        for seq in out.reached:  # each told, however many in one step
            self.recent_reached[self.reached_count % ControlStatus.REACHED_KEPT] = seq
            self.reached_count += 1
            self.last_reached = seq
        if out.reached or now_us >= self.next_status_us:
            self.status_out.publish(self._status(now_us, out, status))
            self.next_status_us = now_us + STATUS_PERIOD_US

    def _set_servos(self, now_us: int, sets: list[tuple[int, int]]) -> None:
        """A mission's DO_SET_SERVO items, handed to the servo output as the link hands the
        command; one on a surface's output is not, and the operator is told."""
        for output, pulse in sets:
            surface = self.surface_outputs.get(output)
            if surface is not None:
                text = f"Mission: output {output} drives the {surface}: not set"
                self.ctx.log.warning("%s", text)
                self.texts.publish(StatusText.of(now_us, d.MAV_SEVERITY_WARNING, text))
                continue
            self.commands.publish(
                VehicleCommand.set_servo(now_us, MISSION_SERVO_SEQ, output, pulse)
            )

    def _set_home(self, t_us: int, items: list[MissionItem]) -> None:
        """A mission's DO_SET_HOME items, handed to the commander, which keeps home."""
        for item in items:
            if item.command == d.MAV_CMD_DO_SET_HOME:
                self.commands.publish(set_home_command(item, t_us, self.controller.home_alt))
                where = "here" if round(item.param1) == 1 else "at the plan's point"
                self.ctx.log.info("mission item %d: home set %s", item.seq, where)
                self._tell(t_us, d.MAV_SEVERITY_INFO, f"Mission: home set {where}")

    def _answer_payloads(self, t_us: int) -> None:
        """A ground station's camera, gripper and actuator commands (the link checked their
        parameters), each answered; taken before this step's photos are judged."""
        for request in self.requests.pending():
            if request.command == CommandId.CAMERA:
                params = tuple(request.param[1:5])
                problem = self.camera.command(round(request.param[0]), params)
            elif request.command == CommandId.GRIPPER:
                problem = self.gripper.act(t_us, round(request.param[0]))
            elif request.command == CommandId.SET_ACTUATOR:
                problem = self.actuators.act(t_us, request.param[:6], round(request.param[6]))
            else:
                continue
            result = CommandResult.DENIED if problem else CommandResult.ACCEPTED
            source = self.ctx.name.encode()
            self.acks.publish(CommandAck.answer(request, t_us, source, result, problem or ""))

    def _configure_payloads(self) -> None:
        payloads = (self.camera, self.gripper, self.actuators)
        configure_payloads(payloads, self.live_params.values, self.surface_outputs)

    def _tell(self, t_us: int, severity: int, text: str) -> None:
        if severity <= d.MAV_SEVERITY_WARNING:
            self.ctx.log.warning("%s", text)
        self.texts.publish(StatusText.of(t_us, severity, text))

    def _home_alt(self) -> float:
        return self.controller.home_alt

    def _say(self, now_us: int) -> None:
        """What the landing told the operator (the pattern it chose, or why none)."""
        said = self.controller.lander.said  # every executor's too (a landing circle)
        for severity, text in said:
            self.ctx.log.info("%s", text)
            self.texts.publish(StatusText.of(now_us, severity, text))
        said.clear()

    def _count(self, refused: bool, t_us: int) -> None:
        """Count the step; an unusable solution or status is said once per stretch of them."""
        if not refused:
            self.ctx.health.ok()
            self.refusing = False
            return
        if not self.refusing:
            self.ctx.log.warning("unusable navigation or status at t=%d us: output held", t_us)
        self.ctx.health.refused += 1
        self.refusing = True

    def _disarm(self, now_us: int, out: ControlOutput, status: VehicleStatus) -> None:
        # The ground station hears the mission complete before the controller stops.
        self.status_out.publish(self._status(now_us, out, status))
        if out.takeoff_phase == TakeoffPhase.ABORTED:
            self.ctx.log.warning("take-off aborted: disarming")
        else:
            self.ctx.log.info(
                "landed and stopped: disarming (%d landing steps on the rangefinder's height)",
                self.controller.lander.range_steps,
            )
        self.commands.publish(VehicleCommand(t_us=now_us, command=int(CommandId.STOP)))
        self.disarm_sent = True

    def _await_output(self) -> None:
        """Once: wait until the servo output plug-in listens before the first command.

        START starts both processes at once; a command sent before the servo output made
        its reader is lost (control/actuators is a Queue), so the first surfaces would go
        out one navigation step later or not at all, as the scheduler ran the two. The
        servo plug-in makes its writer on actuators/servos after its reader.
        """
        if self.output_waited:
            return
        self.output_waited = True
        deadline = time.monotonic() + OUTPUT_WAIT_S
        while self.servo_answers.writers() == 0 and time.monotonic() < deadline:
            time.sleep(0.002)

    def _status(self, now_us: int, out: ControlOutput, status: VehicleStatus) -> ControlStatus:
        msg = ControlStatus(t_us=now_us)
        msg.nav_roll_rad, msg.nav_pitch_rad = out.nav_roll, out.nav_pitch
        msg.target_bearing_rad, msg.wp_dist_m = out.target_bearing, out.wp_dist
        msg.alt_error_m, msg.aspd_error_m_s = out.alt_error, out.aspd_error
        msg.xtrack_error_m, msg.airspeed_m_s = out.xtrack, out.airspeed
        msg.wind_n_m_s, msg.wind_e_m_s = self.controller.wind.wind_ne
        msg.throttle = out.throttle
        executor = self.controller.executor
        running = executor is not None
        msg.mission_seq = executor.current if executor is not None else 0
        finished = executor is not None and executor.finished
        pending = self.controller.set_currents.pending is not None
        flying_it = running and status.mode == FlightMode.MISSION
        msg.mission_state = reported_state(
            flying_it, out.mission_finished, finished, status.mode == FlightMode.RTL, pending
        )
        msg.landed = int(out.landed)
        msg.land_phase, msg.takeoff_phase = out.land_phase, out.takeoff_phase
        msg.reached_count, msg.last_reached = self.reached_count, self.last_reached
        msg.recent_reached[:] = self.recent_reached
        msg.mode_changes = status.changes
        return msg
