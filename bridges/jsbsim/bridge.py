"""The simulator bridge's loop: physics, device bytes, servo bytes, the clock, pacing."""

from __future__ import annotations

import dataclasses
import heapq
import logging
import time
from collections.abc import Callable

from bridges.jsbsim.airframe_file import SimAirframe, read_airframe
from bridges.jsbsim.device_streams import EmulatedDevices
from bridges.jsbsim.failures import DeviceFailures
from bridges.jsbsim.fdm import Flight
from bridges.jsbsim.hil_status import HilStatus
from bridges.jsbsim.lockstep import (
    EXACT_STALL_S,
    STALL_S,
    FlightSync,
    Lockstep,
    RealTime,
    SampleSync,
)
from bridges.jsbsim.options import BridgeOptions
from bridges.jsbsim.ptys import PtyPort
from bridges.jsbsim.rc_receiver import EmulatedReceiver, load_pilot
from bridges.jsbsim.rtcm_listener import RtcmListener
from bridges.jsbsim.serial_lines import SerialLine, open_line
from bridges.jsbsim.servo_card import MiniSscReader
from bridges.jsbsim.truth_log import ServoLog, TruthLog, WheelLog, wheels_path
from bridges.jsbsim.vehicle_commands import VehicleCommands
from bridges.sensor_models.sensor_errors import MagneticField, NoiseModel, SensorErrors
from bridges.sensor_models.true_state import TrueState
from companion.bus.node import BusNode
from companion.messages import SimClock, SimTruth

log = logging.getLogger(__name__)

SENSORS = ("gps", "compass", "imu", "rc", "range")
# What the vehicle's driver of each emulated device publishes (the sim config's drivers).
DEVICE_CHANNELS = {
    # The driver publishes a reading's magnetometer and pressure (a few times a second,
    # its aiding_hz) before its IMU sample: that sample's arrival says they are there too.
    "imu": ("sensors/imu",),
    "compass": ("sensors/compass",),
    "gps": ("sensors/gps",),
    # A Latest channel: the controller and the commander read the sticks' newest frame, so
    # that frame must be this one's, not the one the receiver process had got to.
    "rc": ("sensors/rc",),
    "range": ("sensors/range",),  # the landing's flare steers by it
}
STANDARD_PRESSURE_KPA = 101.325
FAST_LAG_PERIODS = 1  # fast lockstep: how many nav/state periods the vehicle may trail
# Exact: the longest wait for servo bytes an answer says were written (the kernel hands
# them over on a worker thread, which a loaded machine may run late)
SERVO_BYTES_WAIT_S = EXACT_STALL_S
POLL_S = 50e-6
# How long a receiver keeps its RTK fix after the last corrections (a u-blox ZED-F9P holds
# them up to its DGNSS timeout, 60 s by default; the link's radio drops for seconds).
CORRECTIONS_AGE_S = 10.0


def pressure_kpa(alt_msl_m: float) -> float:
    """ISA pressure at an altitude (troposphere)."""
    # Held above the formula's zero (44 km): a diverged model gave a complex pressure.
    return STANDARD_PRESSURE_KPA * max(1.0 - 2.25577e-5 * alt_msl_m, 1e-3) ** 5.25588


def _devices(opts: BridgeOptions) -> EmulatedDevices:
    """The emulated devices, as installed in an airframe unless told otherwise."""
    if opts.mount == "quiet":
        noise = NoiseModel(scale=opts.noise_scale)
    else:
        noise = NoiseModel.installed(opts.noise_scale, calibrated=opts.mount == "calibrated")
    if opts.gps == "rtk":
        noise = noise.with_rtk()
    if opts.gps_wander_m is not None:
        noise = dataclasses.replace(noise, gps_horizontal_m=opts.gps_wander_m)
    errors = SensorErrors(noise, MagneticField(), opts.seed)
    devices = EmulatedDevices(errors, opts.rates, opts.outages, opts.seed)
    if opts.gps == "rtk-mavlink":  # the same seed: the errors it has while uncorrected
        devices.rtk_errors = SensorErrors(noise.with_rtk(), MagneticField(), opts.seed)
        devices.rtk_float_errors = SensorErrors(noise.with_rtk_float(), MagneticField(), opts.seed)
    return devices


def _flight(opts: BridgeOptions, airframe: SimAirframe) -> Flight:
    """The aircraft in JSBSim at its start, in its weather, brakes set."""
    flight = Flight(
        airframe.jsbsim_model,
        opts.physics_hz,
        opts.home,
        opts.airborne_agl_m if opts.airborne else None,
        opts.airborne_speed_m_s or airframe.cruise_speed_m_s,
        opts.airborne_bank_deg,
    )
    flight.set_wind(*opts.wind_ned)
    flight.set_turbulence(opts.turbulence, opts.seed)  # one seed: the same flight
    for servo in airframe.servos.values():
        if servo.surface == "brakes":  # held at their safe setting until commanded
            flight.set_controls({"brakes": servo.command(servo.trim)})
    return flight


def open_ports(opts: BridgeOptions) -> dict[str, PtyPort | SerialLine]:
    """The lines the user wired (hardware in the loop), or a pty for every device."""
    if not opts.hil:
        return {name: PtyPort(name) for name in (*SENSORS, "battery", "servos")}
    ports: dict[str, PtyPort | SerialLine] = {}
    try:
        for name, spec in opts.lines.items():
            ports[name] = open_line(name, spec)
    except ValueError:
        for port in ports.values():
            port.close()
        raise
    return ports


class SimBridge:
    """One simulated aircraft with its devices on ptys."""

    def __init__(self, opts: BridgeOptions) -> None:
        self.opts = opts
        self.airframe = read_airframe(opts.airframe)
        self.flight = _flight(opts, self.airframe)
        self.devices = _devices(opts)
        self.devices.rest_agl_m = self.flight.rest_agl_m
        self.failures = DeviceFailures(opts.seed)
        pilot = load_pilot(opts.pilot_path) if opts.pilot_path else None
        self.receiver = EmulatedReceiver(pilot, opts.rates.rc_hz)
        # The battery monitor is not in lockstep (nothing steers by it at physics rate), so
        # a vehicle without its driver leaves the bridge unhindered.
        self.ports = open_ports(opts)
        self.pending: list[tuple[float, int, str, bytes]] = []  # (release, order, port, data)
        self.order = 0
        self.servo_card = MiniSscReader()
        self.rtcm = RtcmListener()  # corrections the vehicle passes on to its receiver
        self.servo_bytes_in = 0
        self.servo_late = 0  # exact: answers whose bytes did not all come in time
        self.pacer = RealTime(opts.speed) if opts.speed else None
        lockstep = self.pacer is None and opts.sync_hz > 0
        exact = lockstep and opts.exact
        stall_s = EXACT_STALL_S if exact else STALL_S
        self.lockstep = Lockstep([self.ports[n] for n in SENSORS if n in self.ports], stall_s)
        self.truth = TruthLog(opts.truth_path) if opts.truth_path else None
        self.wheels = WheelLog(wheels_path(opts.truth_path)) if opts.truth_path else None
        self.servo_log = ServoLog(opts.servo_log_path) if opts.servo_log_path else None
        # Hardware in the loop: the vehicle runs apart, on its own clock; no bus to share.
        self.bus = None if opts.hil else BusNode(opts.namespace, "sim_bridge")
        self.clock = self.bus.writer("sim/clock") if self.bus else None
        self.truth_out = self.bus.writer("sim/truth") if self.bus else None
        self.hil_status = HilStatus(self.ports) if opts.hil else None
        self.sync: FlightSync | None = None
        self.nav_sync: FlightSync | None = None
        self.navigated: FlightSync | None = None
        self.samples: SampleSync | None = None
        self.logged: FlightSync | None = None
        if lockstep:
            self._keep_in_step(round(1e6 / opts.sync_hz), exact)
        self.commands = (
            VehicleCommands(
                self.bus, self.failures, self.sync, opts.start_at_s, self.navigated, opts.hold_at_s
            )
            if self.bus
            else None
        )
        if self.commands is not None and self.clock is not None:
            self.commands.on_hold = self.clock.update_connections
        self.frames = 0
        self.stopping = False
        if self.clock is not None:
            self.clock.publish(SimClock(t_us=0, frame=0))

    def _keep_in_step(self, period_us: int, exact: bool) -> None:
        """Lockstep with the vehicle's navigator and control loop (and, exact, its samples)."""
        # Fast lockstep lets the vehicle trail by a period (it runs beside the physics)
        # but never further: a late process holds the simulation, whatever the load.
        lag = 0 if exact else FAST_LAG_PERIODS
        assert self.bus is not None  # lockstep is refused with hardware in the loop
        answers = self.bus.latest_reader("actuators/servos")
        self.sync = FlightSync(period_us, answers, self.bus.waiter([answers]), lag)
        nav = self.bus.latest_reader("nav/state")
        self.navigated = FlightSync(period_us, nav, self.bus.waiter([nav]), 0, "t_us", True)
        # The navigator answers every grid state, armed or not. Exact lockstep waits for
        # it from its first state on: a navigator left behind before the arming (nothing
        # else holds the simulation then) lost samples from its queues on a busy machine
        # and navigated differently from the same run on an idle one.
        nav = self.bus.latest_reader("nav/state")
        waiter = self.bus.waiter([nav])
        self.nav_sync = FlightSync(period_us, nav, waiter, lag, "t_us", True, from_start=exact)
        if exact:
            readers = {
                device: {c: self.bus.reader(c) for c in channels}
                for device, channels in DEVICE_CHANNELS.items()
            }
            every = [r for by_channel in readers.values() for r in by_channel.values()]
            self.samples = SampleSync(readers, self.bus.waiter(every))
            # The flight log's reader, a period behind at most, so its queues never overflow.
            logged = self.bus.latest_reader("system/logged")
            self.logged = FlightSync(period_us, logged, self.bus.waiter([logged]), 1, "t_us", True)
        for holding in (self.sync, self.navigated, self.nav_sync, self.samples, self.logged):
            if holding is not None and self.clock is not None:
                holding.on_hold = self.clock.update_connections

    def device_paths(self) -> dict[str, str]:
        """Device name → the pty path the vehicle's driver opens."""
        return {name: port.path for name, port in self.ports.items()}

    def run(self, hold: Callable[[], None] | None = None) -> None:
        """Fly until ``duration_s`` of simulation time or ``stop()``."""
        if hold is not None:
            hold()
        started = time.monotonic()
        end = self.opts.duration_s
        while not self.stopping and (end is None or self.flight.t_s < end - 1e-9):
            self.step()
        wall = time.monotonic() - started
        sync = self.sync
        log.info(
            "simulated %.1f s in %.1f s wall (%.1fx); lockstep stalls %d; control stalls %s",
            self.flight.t_s,
            wall,
            self.flight.t_s / wall if wall else 0.0,
            self.lockstep.stalls,
            "-" if sync is None else self._sync_summary(),
        )

    def _sync_summary(self) -> str:
        sync, nav, samples = self.sync, self.nav_sync, self.samples
        assert sync is not None
        text = f"{sync.stalls} (waited {sync.wait_s:.1f} s)"
        if nav is not None:
            text += f"; nav stalls {nav.stalls} (waited {nav.wait_s:.1f} s)"
        if samples is not None:
            text += f"; late samples {samples.late} (waited {samples.wait_s:.1f} s)"
            text += f"; late servo bytes {self.servo_late}"
        return text

    def stop(self) -> None:
        """Ask the loop to end after the current frame (also ends any wait for the vehicle)."""
        self.stopping = True
        for waiting in (self.sync, self.nav_sync, self.navigated, self.samples, self.logged):
            if waiting is not None:
                waiting.cancelled = True
        if self.commands is not None:
            self.commands.cancelled = True

    def step(self) -> None:
        """One physics frame, then what the devices say about it, then pacing."""
        self.flight.step()
        self.frames += 1
        s = self.flight.state()
        t_us = round(s.t_s * 1e6)
        if self.clock is not None:
            self.clock.publish(SimClock(t_us=t_us, frame=self.frames))
        self._publish_truth(s, t_us)
        throttle = self.flight.controls()["throttle"]
        due = self.devices.due(s, pressure_kpa(s.alt_msl_m), throttle)
        if (frame := self.receiver.due(s.t_s)) is not None:
            due.append(("rc", s.t_s, frame))
        for name, release, measured in due:
            data = self.failures.filter(name, measured)
            if data is None:
                continue
            heapq.heappush(self.pending, (release, self.order, name, data))
            self.order += 1
        written = set()
        while self.pending and self.pending[0][0] <= s.t_s + 1e-9:
            _, _, name, data = heapq.heappop(self.pending)
            if (port := self.ports.get(name)) is not None:  # HIL: not every device is wired
                port.write(data)
                written.add(name)
        if "gps" in written:  # the receiver hears what the vehicle wrote it at its epochs
            self.rtcm.feed(self.ports["gps"].read(), s.t_s)
            self.devices.corrected_until_s = self.rtcm.last_good_s + CORRECTIONS_AGE_S
        sampled: set[str] | None = None  # exact: the devices whose samples came this frame
        if self.samples is not None:  # sleeps on the bus: the pty check after is quick
            # A device whose driver stopped reading (or never ran) is not waited for.
            live = {n for n in written if self.lockstep.waiting_for.get(n, True)}
            sampled = live - self.failures.garbled()
            self.samples.wait(sampled, t_us)
        if self.pacer is not None:
            self.pacer.wait(s.t_s)
        else:
            self.lockstep.wait()
        if self.commands is not None and self.commands.serve(t_us) and self.pacer is not None:
            self.pacer.restart()  # real time goes on from the held frame, not catching up
        # Exact: the navigator answers the grid once an IMU sample at or past its tick came.
        if self.nav_sync is not None and (sampled is None or "imu" in sampled):
            self.nav_sync.wait(t_us)
        if self.sync is not None:
            self.sync.wait(t_us)
        if self.logged is not None:
            self.logged.wait(t_us)
        self._apply_servos()

    def _publish_truth(self, s: TrueState, t_us: int) -> None:
        if self.truth is not None:
            self.truth.add_state(s)
        if self.wheels is not None:
            self.wheels.add(s.t_s, self.flight.weight_on_wheels())
        if self.hil_status is not None:
            self.hil_status.report(s, self.servo_bytes_in)
        if self.truth_out is None:
            return
        self.truth_out.publish(
            SimTruth(
                t_us,
                s.roll,
                s.pitch,
                s.yaw,
                s.lat_deg,
                s.lon_deg,
                s.alt_msl_m,
                s.alt_agl_m,
                s.vn,
                s.ve,
                s.vd,
                s.airspeed_m_s,
            )
        )

    def _servo_bytes(self) -> bytes:
        """What the servo plug-in wrote; exact lockstep takes every byte its answer counts.

        The kernel hands a pty's bytes to the other side a moment after the write returns,
        so one read may miss the end of what was written just before the answer.
        """
        data = self.ports["servos"].read()
        self.servo_bytes_in += len(data)
        answer = self.sync.answers.get() if self.samples is not None and self.sync else None
        if answer is None or answer.bytes_out <= self.servo_bytes_in:
            return data
        deadline = time.monotonic() + SERVO_BYTES_WAIT_S
        chunks = [data]
        while answer.bytes_out > self.servo_bytes_in and time.monotonic() < deadline:
            time.sleep(POLL_S)
            chunks.append(chunk := self.ports["servos"].read())
            self.servo_bytes_in += len(chunk)
        if answer.bytes_out > self.servo_bytes_in:
            # The rest moves the surfaces a frame late: not the same flight as another run.
            log.warning(
                "lockstep: servo bytes of the command at %.2f s missing", answer.command_t_us / 1e6
            )
            self.servo_late += 1
        return b"".join(chunks)

    def _apply_servos(self) -> None:
        commands = self.servo_card.read(self._servo_bytes())
        if not commands:
            return
        controls = {}
        for received in commands:
            servo = self.airframe.servos.get(received.servo)
            if servo is not None:
                controls[servo.surface] = servo.command(received.position)
        self.flight.set_controls(controls)
        if self.servo_log is not None:
            self.servo_log.add(self.flight.t_s, controls)

    def close(self) -> None:
        """Release the ptys, the truth file and the bus."""
        if self.rtcm.messages or self.rtcm.bad:
            log.info("%s", self.rtcm.summary())
        if self.truth is not None:
            self.truth.close()
        if self.wheels is not None:
            self.wheels.close()
        if self.servo_log is not None:
            self.servo_log.close()
        for port in self.ports.values():
            port.close()
        if self.bus is not None:
            self.bus.close()
