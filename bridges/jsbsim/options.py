"""Everything a simulation run can be told, in one JSON-able record."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field

from bridges.jsbsim.conditions import TURBULENCE, Home

# How the sensors sit in the airframe (bridges/sensor_models/sensor_errors.py NoiseModel):
# no defects, the residue of a good calibration, or the iron and motor field as they are.
MOUNTS = ("quiet", "calibrated", "uncalibrated")
# A consumer receiver; one holding an RTK fix on corrections of its own (NoiseModel.with_rtk);
# one holding it while the vehicle writes it RTCM3 corrections from the ground station.
GPS_RECEIVERS = ("standard", "rtk", "rtk-mavlink")
# The aircraft's serial devices, as the bridge names them (hardware in the loop: --gps ...).
DEVICES = ("gps", "compass", "imu", "rc", "battery", "range", "servos")


@dataclass
class Outage:
    """A window of simulation time with no GPS fix."""

    start_s: float
    duration_s: float

    def covers(self, t_s: float) -> bool:
        """Whether ``t_s`` falls in the window."""
        return self.start_s <= t_s < self.start_s + self.duration_s


@dataclass
class DeviceRates:
    """How often each device talks, and the GPS's latency."""

    imu_hz: float = 100.0
    compass_hz: float = 20.0
    gps_hz: float = 5.0
    # A receiver sends its fix a computation after the epoch it describes, and not always
    # equally late: each epoch's latency is drawn uniformly within ± the jitter.
    gps_latency_s: float = 0.12
    gps_latency_jitter_s: float = 0.03
    rc_hz: float = 50.0  # SBUS receivers send every 7-20 ms
    battery_hz: float = 10.0
    range_hz: float = 100.0  # a TFmini's default frame rate


@dataclass
class BridgeOptions:
    """A simulation run: aircraft, start, weather, sensors, pace."""

    airframe: str = "c172p"  # airframe name or TOML path (its jsbsim_model is flown)
    home: Home = field(default_factory=Home)
    airborne: bool = False
    airborne_agl_m: float = 300.0
    airborne_speed_m_s: float | None = None  # None: the airframe's cruise speed
    airborne_bank_deg: float = 0.0  # right wing down; trimmed level, then rolled into it
    speed: float | None = None  # real-time factor; None: lockstep, as fast as consumed
    physics_hz: float = 100.0
    exact: bool = False  # lockstep also with the control loop (companion sim --exact)
    start_at_s: float | None = None  # arm and start the mission at this simulated second
    # Hold the simulation at this simulated second until a ground station has armed the
    # vehicle and started its mission (bridges/jsbsim/vehicle_commands.py).
    hold_at_s: float | None = None
    sync_hz: float = 0.0  # the vehicle's nav/state grid, for exact lockstep; 0: off
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0)
    turbulence: str = "none"
    outages: list[Outage] = field(default_factory=list)
    rates: DeviceRates = field(default_factory=DeviceRates)
    noise_scale: float = 1.0
    # The GPS's slowly wandering error, metres per axis before noise_scale; None: the
    # receiver model's own (NoiseModel.gps_horizontal_m). 0 leaves only its white noise.
    gps_wander_m: float | None = None
    gps: str = "standard"  # the GPS receiver: one of GPS_RECEIVERS
    mount: str = "calibrated"  # the sensors' airframe defects: one of MOUNTS
    seed: int = 1
    duration_s: float | None = None
    truth_path: str | None = None
    pilot_path: str | None = None  # the scripted RC pilot (rc_receiver.py); None: hands off
    servo_log_path: str | None = None  # the surface commands received, by simulation time
    namespace: str = "companion"
    hold: bool = False  # wait for "run" on stdin before the first step
    # Hardware in the loop: device -> the serial line it is wired to (serial_lines.py). The
    # vehicle runs apart, on its own clock: real time, no bus, devices not named stay silent.
    lines: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.turbulence not in TURBULENCE:
            raise ValueError(f"turbulence must be one of {', '.join(TURBULENCE)}")
        if self.mount not in MOUNTS:
            raise ValueError(f"mount must be one of {', '.join(MOUNTS)}")
        if self.gps not in GPS_RECEIVERS:
            raise ValueError(f"gps must be one of {', '.join(GPS_RECEIVERS)}")
        if self.gps != "standard" and self.gps_wander_m is not None:
            raise ValueError("the GPS wander is the standard receiver's (an RTK fix has its own)")
        if not -80.0 <= self.airborne_bank_deg <= 80.0:
            raise ValueError("the airborne start's bank must lie within ±80°")
        if self.gps_wander_m is not None and not 0.0 <= self.gps_wander_m <= 100.0:
            raise ValueError("the GPS wander must lie within 0-100 m")
        if self.speed is not None and self.speed <= 0:
            raise ValueError("speed must be positive (or None for lockstep)")
        if self.start_at_s is not None and self.hold_at_s is not None:
            raise ValueError("start-at arms the vehicle itself; hold-at waits for a ground station")
        if self.lines:
            self._check_hardware_in_the_loop()

    @property
    def hil(self) -> bool:
        """Whether the devices are on real lines to a vehicle running apart."""
        return bool(self.lines)

    def _check_hardware_in_the_loop(self) -> None:
        unknown = sorted(set(self.lines) - set(DEVICES))
        if unknown:
            raise ValueError(f"no such device: {', '.join(unknown)} (one of {', '.join(DEVICES)})")
        if "servos" not in self.lines:
            raise ValueError("hardware in the loop needs the servo line (--servos)")
        if self.speed != 1.0:
            raise ValueError("hardware in the loop runs in real time (speed 1)")
        if self.exact or self.start_at_s is not None or self.hold or self.sync_hz:
            raise ValueError("lockstep, start-at and hold need the vehicle on this bus")
        if self.hold_at_s is not None:
            raise ValueError("hold-at needs the vehicle on this bus")

    def to_json(self) -> str:
        """The options as one JSON line."""
        return json.dumps(dataclasses.asdict(self))

    @classmethod
    def from_json(cls, text: str) -> BridgeOptions:
        """Inverse of ``to_json``."""
        data = json.loads(text)
        data["home"] = Home(**data["home"])
        data["rates"] = DeviceRates(**data["rates"])
        data["outages"] = [Outage(**o) for o in data["outages"]]
        data["wind_ned"] = tuple(data["wind_ned"])
        return cls(**data)
