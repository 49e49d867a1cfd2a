"""``link.mavlink``: the vehicle's MAVLink endpoints (group ``core``).

Reads bytes from every endpoint, lets pymavlink frame them, routes messages addressed to
other systems between endpoints (as mavlink-router does), dispatches the vehicle's own to
one service per microservice, and streams telemetry built from the bus. Commands other
plug-ins act on go onto ``link/commands``; their answers come back on
``link/command_acks`` and become COMMAND_ACKs.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from companion.control.device_watch import RC_RECEIVER, DeviceWatch
from companion.control.mission.mission_files import MissionStore
from companion.control.modes import INITIAL_MODE
from companion.control.prearm import PREARM_PARAMS, Readiness, failures
from companion.flight_log import LogDirectory
from companion.link.camera_feedback import CAPTURES, CameraFeedback
from companion.link.codec import MavlinkStream, new_encoder
from companion.link.codec import dialect as d
from companion.link.command_service import CommandService
from companion.link.commands import BUS_ACK_TIMEOUT_S, register_commands
from companion.link.commands.held import HeldCommands
from companion.link.endpoints import endpoint_problems, open_endpoints, serial_endpoints
from companion.link.flight_messages import mission_items_reached
from companion.link.gcs_watch import GcsWatch
from companion.link.heartbeat_state import HeartbeatFollower
from companion.link.identity import IdentityService
from companion.link.link_router import LinkRouter
from companion.link.log_transfer import LogTransferService
from companion.link.manual_control import ManualControlService
from companion.link.metadata_service import MetadataService
from companion.link.microservice import Outgoing, Service, refused_count
from companion.link.mission_service import MissionService
from companion.link.mode_messages import current_mode
from companion.link.params_service import ParamsService
from companion.link.px4_compat import PX4_PARAMS, vehicle_facts
from companion.link.refusal_texts import RefusalTexts
from companion.link.rtcm_inject import RtcmInjectService
from companion.link.shell_service import ShellService
from companion.link.signing import configured_secret, key_file_problem, key_from
from companion.link.snapshot import SNAPSHOT_CHANNELS, Snapshot, snapshot_readers
from companion.link.statustext import StatusTexts
from companion.link.timesync import TimesyncService
from companion.messages import ControlStatus, FlightMode, LinkStatus, ParamChange, VehicleCommand
from companion.params import ParamDecl, ParamStore
from companion.plugin import NO_VEHICLE, DeviceProbe, Plugin, PluginContext, Setting

MAX_WAIT_S = 1.0  # longest sleep: a stream or a timer falling due, or a trigger, ends it
PREARM_PERIOD_S = 1.0  # SYS_STATUS's ready-to-arm bit is judged once a second
RELAYED = ("link/command_acks", "vehicle/statustext", CAPTURES)
COMMANDER = "vehicle.commander"
STREAM_PARAMS = {
    "SR_ATTITUDE": (d.MAVLINK_MSG_ID_ATTITUDE,),
    "SR_POSITION": (d.MAVLINK_MSG_ID_GLOBAL_POSITION_INT, d.MAVLINK_MSG_ID_VFR_HUD),
    "SR_GPS": (d.MAVLINK_MSG_ID_GPS_RAW_INT,),
}  # telemetry and acks from the bus are looked at this often at least
AUTOPILOTS = {"generic": d.MAV_AUTOPILOT_GENERIC, "px4": d.MAV_AUTOPILOT_PX4}
CAPABILITIES = (
    d.MAV_PROTOCOL_CAPABILITY_MISSION_INT
    | d.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
    | d.MAV_PROTOCOL_CAPABILITY_MAVLINK2
    | d.MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST
    | d.MAV_PROTOCOL_CAPABILITY_MISSION_FENCE
    | d.MAV_PROTOCOL_CAPABILITY_MISSION_RALLY
    | d.MAV_PROTOCOL_CAPABILITY_FTP  # read-only: the component metadata files
)


class MavlinkLink(Plugin):
    """The MAVLink side of the vehicle."""

    wants_vehicle_tables = True  # it serves every plug-in's parameters
    settings = {
        "endpoints": Setting(
            list,
            ["udpout://127.0.0.1:14550", "udpout://127.0.0.1:14540"],
            "endpoint URLs: udpout://, udpin://, tcpin://, serial:///dev/X:BAUD;"
            " options as a query: ?budget=BYTES_PER_S&tlog=PATH",
        ),
        "compid": Setting(int, 1, "MAVLink component id of the autopilot", min=1, max=255),
        # PX4: the QGroundControl plug-in that offers every guided action for a fixed wing
        # (companion.control.modes says why); generic: no guided action in QGroundControl.
        "autopilot": Setting(str, "px4", "MAV_AUTOPILOT reported", choices=tuple(AUTOPILOTS)),
        "signing_key": Setting(str, "", "signing key: the ground station's text (SHA-256)"),
        # Kept out of the config (which is shown and copied), readable by the vehicle only.
        "signing_key_file": Setting(str, "", "file holding the signing key (as signing_key)"),
    }
    params = (
        ParamDecl("SR_ATTITUDE", 10.0, 0.0, 100.0, "Hz", "ATTITUDE rate on every endpoint"),
        ParamDecl("SR_POSITION", 5.0, 0.0, 50.0, "Hz", "GLOBAL_POSITION_INT and VFR_HUD rate"),
        ParamDecl("SR_GPS", 2.0, 0.0, 10.0, "Hz", "GPS_RAW_INT rate"),
        ParamDecl.switch("SYS_FAILURE_EN", 0.0, "accept MAV_CMD_INJECT_FAILURE (simulator)"),
        *PREARM_PARAMS,
        *PX4_PARAMS,
    )
    # What telemetry shows (the snapshot's channels), and the acks, texts and photos it relays.
    optional_inputs = (*SNAPSHOT_CHANNELS.values(), *RELAYED)
    outputs = ("link/commands", "params/changes", "link/status", "mission/changed",
               "link/manual_control", "link/gps_inject")  # fmt: skip

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        key, key_file = settings["signing_key"], settings["signing_key_file"]
        both = ["give signing_key or signing_key_file, not both"] if key and key_file else []
        return both or endpoint_problems(settings["endpoints"], key or key_file)

    @classmethod
    def probe(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[DeviceProbe]:
        """The radios (the ground station may be off: their silence is no failure)."""
        radios = serial_endpoints(settings["endpoints"])
        stream = MavlinkStream
        return [DeviceProbe(p, b, stream(), must_answer=False, what="radio") for p, b in radios]

    @classmethod
    def bench_problems(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """The signing key file can be read."""
        problem = key_file_problem(settings["signing_key_file"])
        return [problem] if problem else []

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        sysid = int(ctx.vehicle.get("sysid", 1))
        self.mav = new_encoder(sysid, ctx.settings["compid"])
        self.endpoints = open_endpoints(ctx.settings["endpoints"])
        autopilot = AUTOPILOTS[ctx.settings["autopilot"]]
        self.identity = IdentityService(self.mav, sysid, autopilot, CAPABILITIES)
        # The heartbeat waits for a commander's status; modes PX4's or ArduPlane's numbers.
        px4, commander = autopilot == d.MAV_AUTOPILOT_PX4, COMMANDER in ctx.plugins
        self.heartbeat = HeartbeatFollower(self.identity.state, commander, time.monotonic(), px4)
        self.commands = CommandService(self.mav, sysid, ctx.settings["compid"])
        self.snapshot = Snapshot(assumed_mode=self.heartbeat.assumed, px4_modes=px4)
        self.devices = DeviceWatch(ctx.plugins)  # silent or garbled devices refuse arming
        self.boot_us = ctx.clock.now_us()
        bus = ctx.bus
        self.readers = snapshot_readers(bus)
        self.acks = bus.queue_reader("link/command_acks")
        self.to_vehicle = bus.writer("link/commands")
        self.held = HeldCommands()  # commands for a flight plug-in not yet listening
        self.param_changes = bus.writer("params/changes")
        self.link_status = bus.writer("link/status")
        self.texts = bus.queue_reader("vehicle/statustext")
        # SYS_STATUS's checks' next time; items the controller reached (-1: not heard yet).
        self.next_prearm_s, self.reached_count = 0.0, -1
        self.timesync = TimesyncService(
            self.mav, lambda: ctx.clock.now_us() * 1000, sysid, ctx.settings["compid"]
        )
        services: list[Service] = [self.identity, self.commands, self.timesync]
        secret = configured_secret(ctx.settings["signing_key"], ctx.settings["signing_key_file"])
        key = key_from(secret) if secret else None
        self.refusal_text = RefusalTexts(self.statustext, time.monotonic)
        self.texts_out = StatusTexts(self.mav)
        self.router = LinkRouter(self.mav, self.endpoints, services, key)
        self.gcs = GcsWatch()
        self.router.add_service(self.gcs)
        self.router.add_service(CameraFeedback(self.mav, bus.queue_reader(CAPTURES).drain))
        self._serve_ground_inputs(ctx, sysid)
        self._serve_params(ctx, sysid)
        self._serve_missions(ctx, sysid)
        self._serve_logs(ctx, sysid)
        register_commands(
            self.commands, self, self.identity, self.router, self.metadata, self._params_service,
            self.missions,
        )  # fmt: skip
        self.commands.on_refusal = self.refusal_text
        # Woken by an ack, a text, a change of mode or arming (announced at once), and a
        # navigation state when a stream carrying it is due.
        r = self.readers
        self.waker = bus.gated_waiter(r["nav"], (self.acks, self.texts, r["status"], r["health"]))
        self.nav_at_s = float("-inf")
        self._seq = 0

    def _serve_ground_inputs(self, ctx: PluginContext, sysid: int) -> None:
        """The ground station's joystick, and its RTK base's corrections for the GPS."""
        joystick, now_us = ctx.bus.writer("link/manual_control"), ctx.clock.now_us
        self.manual = ManualControlService(sysid, joystick.publish, now_us, self.refusal_text)
        self.rtcm = RtcmInjectService(ctx.bus.writer("link/gps_inject").publish, now_us)
        self.router.add_service(self.manual, self.rtcm)

    def _serve_missions(self, ctx: PluginContext, sysid: int) -> None:
        store = MissionStore(Path(ctx.vehicle.get("state_dir", ".")) / "missions")
        self.missions = m = MissionService(self.mav, store, sysid, ctx.settings["compid"])
        self.router.add_service(m)
        # The other plug-ins follow the stored lists through this, not the files' times.
        self.mission_changes = ctx.bus.writer("mission/changed")
        m.on_change, m.say, m.refusal = self._mission_changed, self.statustext, self.refusal_text
        self._mission_changed(0)

    def _serve_logs(self, ctx: PluginContext, sysid: int) -> None:
        """The flight logs system.logger writes, for QGroundControl's Log Download page."""
        logs = LogDirectory(Path(ctx.vehicle.get("state_dir", ".")) / "logs", budget_bytes=0)
        budgets = self.router.budgets
        self.log_transfer = LogTransferService(
            self.mav, logs, sysid, ctx.settings["compid"],
            rate_bytes_s=lambda i: budgets[i].rate_bytes_s * budgets[i].scale,
            armed=self._armed_now,
        )  # fmt: skip
        self.log_transfer.on_refusal = self.refusal_text
        self.router.add_service(self.log_transfer)

    def _armed_now(self) -> bool:
        """Armed as the health table says at this moment (not as of the last step)."""
        health = self.readers["health"].get()
        return health is not None and bool(health.flight_running)

    def _mission_changed(self, mission_type: int) -> None:
        now = self.ctx.clock.now_us()
        self.mission_changes.publish(self.missions.store.changed(mission_type, now))

    def _serve_params(self, ctx: PluginContext, sysid: int) -> None:
        decls = vehicle_facts(ctx.param_decls or self.params, sysid, ctx.plugins)
        self.store = ParamStore(decls, Path(ctx.vehicle.get("state_dir", ".")) / "params.json")
        self.store.migrate()  # the link owns the file: an old one takes the new form now
        service = ParamsService(self.mav, self.store, sysid, ctx.settings["compid"])
        service.on_refusal = self.refusal_text
        service.on_change = self._param_changed
        self.router.add_service(service)
        self._apply_rates()
        self._params_service = service
        self.metadata = MetadataService(self.mav, self.store.decls.values(), sysid, service.compid)
        self.router.add_service(self.metadata)
        self.router.add_service(ShellService(self.mav, self.readers["health"].get, self.store))

    def _param_changed(self, name: str, value: float) -> None:
        """Tell the parameter's owner (it follows params/changes) and apply our own."""
        change = ParamChange(t_us=self.ctx.clock.now_us(), value=value)
        change.name = name.encode()[:16]
        self.param_changes.publish(change)
        self._apply_rates()

    def _apply_rates(self) -> None:
        """The SR_* parameters set every endpoint's default stream rates."""
        for name, streams in STREAM_PARAMS.items():
            if name not in self.store.decls:
                continue
            hz = self.store.get(name)
            for schedule in self.router.schedules:
                for msg_id in streams:
                    schedule.set_interval(msg_id, 1e6 / hz if hz > 0 else -1)

    def statustext(self, text: str, severity: int = d.MAV_SEVERITY_WARNING) -> None:
        """Tell every ground station (refusals, failsafes)."""
        out = [Outgoing(msg, None) for msg in self.texts_out.encode(text, severity)]
        self.router.send(out, time.monotonic())

    def _refresh_snapshot(self) -> None:
        s = self.snapshot
        for key, reader in self.readers.items():
            setattr(s, key, reader.get())
        self.devices.update(s.health)
        self.held.follow(s.health, self.ctx.clock.now_us())
        self.held.release(s.health, time.monotonic(), self.to_vehicle.publish)
        s.control = self._fresh_control(s.control)
        s.now_us = self.ctx.clock.now_us()
        if s.status is not None and s.status.home_valid:  # home is the commander's alone
            s.home = (s.status.home_lat_deg, s.status.home_lon_deg, s.status.home_alt_msl_m)
            s.home_alt_m = s.status.home_alt_msl_m
        if time.monotonic() >= self.next_prearm_s:  # for SYS_STATUS: a second is often enough
            self.next_prearm_s = time.monotonic() + PREARM_PERIOD_S
            armed = s.health is not None and bool(s.health.flight_running)
            checks = self.param("ARMING_CHECK") >= 0.5
            s.prearm_ok = armed or not checks or not self.prearm_failures()
        self.missions.describe(s)
        s.fence_enabled = self.store.values.get("FENCE_ENABLE", 0.0) >= 0.5  # the commander's
        s.time_boot_ms = max(0, (self.ctx.clock.now_us() - self.boot_us) // 1000) & 0xFFFFFFFF
        s.unix_us = time.time_ns() // 1000
        if self.heartbeat.update(s.status, s.health, time.monotonic()):
            # A change of mode is announced at once, not at the stream's next turn.
            msg = current_mode(self.mav, s.status, px4=s.px4_modes)
            if msg is not None:
                self.router.send([Outgoing(msg, None)], time.monotonic())

    def _fresh_control(self, control: ControlStatus | None) -> ControlStatus | None:
        """The controller's status while it runs; MISSION_ITEM_REACHED when it grows."""
        if control is None or not control.fresh(self.ctx.clock.now_us()):
            return None
        reached = mission_items_reached(self.mav, control, self.reached_count)
        self.router.send([Outgoing(msg, None) for msg in reached], time.monotonic())
        self.reached_count = control.reached_count
        self.missions.follow(control.mission_state, control.mission_seq)
        return control

    def _wait_input(self, now_s: float) -> None:
        nav_known = self.snapshot.nav is not None
        timeout, nav_wanted = self.router.next_wake(now_s, MAX_WAIT_S, nav_known)
        fd_owner = {fd: ep for ep in self.endpoints for fd in ep.filenos()}
        # Watched from one wait to the next while no endpoint closed or opened one.
        fds, changes = list(fd_owner), sum(ep.fd_changes for ep in self.endpoints)
        woken, ready = self.waker.wait_with_fds(timeout, fds, nav_wanted, changes)
        # Woken by the timer only to open the gate (ATTITUDE's time): on to the next state at
        # once, not a whole step for nothing first; what falls due before it ends the sleep.
        while not (woken or ready or nav_wanted):
            timeout, nav_wanted = self.router.next_wake(time.monotonic(), MAX_WAIT_S, nav_known)
            if not nav_wanted or timeout <= 0.0:
                break
            self.readers["nav"].get()  # the state from before the gate opened: not the one
            woken, ready = self.waker.wait_with_fds(timeout, fds, nav_wanted, changes)
        if self.readers["nav"] in woken:
            self.nav_at_s = time.monotonic()
        for fd in ready:
            self.router.receive(fd_owner[fd], fd, time.monotonic())

    def step(self) -> None:
        self._wait_input(time.monotonic())
        now_s = time.monotonic()
        out: list[Outgoing] = []
        reasons = []
        for ack in self.acks.drain():
            out += self.commands.complete(ack.seq, ack.result, now_s)
            if ack.reason:
                reasons.append(ack.reason.decode(errors="replace"))
        self._refresh_snapshot()
        out += self.router.tick(now_s)
        self.router.send(out, now_s)
        for reason in reasons:  # after the ack: a ground station waits for that first
            self.statustext(reason)
        for text in self.texts.drain():  # failsafes and other plug-ins' announcements
            self.statustext(text.text.decode(errors="replace"), text.severity)
        if self.gcs.status_due(now_s):
            status = LinkStatus(t_us=self.ctx.clock.now_us())
            status.gcs_silence_s = self.gcs.silence_s(now_s)
            self.link_status.publish(status)
        self.router.stream_telemetry(self.snapshot, now_s, self.nav_at_s)
        counts = self.router.counters
        self.ctx.health.frames_ok, self.ctx.health.frames_bad = counts.ok, counts.bad
        parts = self.commands, self._params_service, self.missions, self.manual, self.metadata
        services = (*parts, self.log_transfer, self.timesync)
        self.ctx.health.refused = refused_count(services)

    def has_commander(self) -> bool:
        """Whether the vehicle runs a commander to answer mode commands."""
        if self.readers["status"].get() is not None:
            return True
        health = self.readers["health"].get()
        return health is not None and health.row_of_kind(COMMANDER.encode()) is not None

    def param(self, name: str) -> float:
        """One of the link's own parameters (VehiclePort)."""
        return self.store.get(name)

    def prearm_failures(self) -> list[str]:
        """Why arming would be refused now, from what the link sees (VehiclePort)."""
        snap = self.snapshot
        mode = INITIAL_MODE
        if snap.status is not None and snap.status.mode in FlightMode._value2member_map_:
            mode = FlightMode(snap.status.mode)
        items, now = self.missions.store.items, self.ctx.clock.now_us()
        # A joystick flying the aircraft stands in for a silent RC receiver (PX4's "RC and
        # Joystick with fallback"); without one the receiver must speak.
        devices = self.devices.failures(excused=(RC_RECEIVER,) if self.manual.flying(now) else ())
        r = Readiness(
            now_us=now, nav=snap.nav, gps=snap.gps, imu=snap.imu, mode=mode,
            mag=snap.mag, compass=snap.compass, baro=snap.baro, devices=devices,
            mission=items[d.MAV_MISSION_TYPE_MISSION], fence=items[d.MAV_MISSION_TYPE_FENCE],
        )  # fmt: skip
        return failures(r, self.store.values, self.missions.verdicts)

    def open_imu(self) -> Any:
        """A reader of every IMU sample, while a sensor calibration runs (VehiclePort)."""
        return self.ctx.bus.queue_reader("sensors/imu")

    @property
    def simulated(self) -> bool:
        """Whether the vehicle runs on the simulator's clock (VehiclePort)."""
        return self.ctx.vehicle.get("clock") == "sim"

    def publish_command(
        self, command: int, params: tuple[float, ...] = (), to: bytes | None = None
    ) -> int:
        """Put a VehicleCommand on the bus (for the flight plug-in of kind ``to``, once it
        listens: ``HeldCommands``); returns its sequence number for the ack."""
        self._seq += 1
        msg = VehicleCommand(t_us=self.ctx.clock.now_us(), seq=self._seq, command=command)
        for i, value in enumerate(params[:7]):
            msg.param[i] = value
        if to is not None and not self.held.listening(self.snapshot.health, to):
            self.held.hold(to, time.monotonic() + BUS_ACK_TIMEOUT_S, msg)
        else:
            self.to_vehicle.publish(msg)
        return self._seq

    def close(self) -> None:
        self.waker.close()
        self.router.close()
        for endpoint in self.endpoints:
            endpoint.close()
