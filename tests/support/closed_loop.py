"""The flight controller flying JSBSim in one process, on the true state.

No sensors, no bus: the control laws and the mission executor against the real flight
model, at hundreds of times real time. Used by the control tests and for tuning; the
whole vehicle (drivers, navigator, link, servo card) is flown by ``companion sim``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bridges.jsbsim.fdm import Flight, Home
from companion.actuators.airframe import load_airframe
from companion.control.flight.attitude_modes import Sticks
from companion.control.flight.controller import ControlOutput, FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.items import MissionItem
from companion.geodesy import LocalFrame
from companion.messages import FlightMode, NavFlags, NavState, RangeReading, VehicleStatus
from mavlink_dialect import companion as d

PHYSICS_HZ = 100
CONTROL_EVERY = 2  # control at 50 Hz


@dataclass
class Sample:
    """One control step: time, truth and what the controller said."""

    t_s: float
    lat: float
    lon: float
    alt_msl: float
    alt_agl: float
    airspeed: float
    roll: float
    yaw: float
    out: ControlOutput
    vel_ned: tuple[float, float, float] = (0.0, 0.0, 0.0)
    on_wheels: bool = False  # JSBSim: a wheel carries weight


@dataclass
class ClosedLoop:
    """One aircraft, its controller, and the record of the flight."""

    airframe: str = "c172p"
    items: list[MissionItem] = field(default_factory=list)
    mode: FlightMode = FlightMode.MISSION
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0)
    turbulence: str = "none"
    airborne_agl_m: float | None = None
    overrides: dict[str, float] = field(default_factory=dict)
    sticks: Sticks | None = None  # a pilot's, for Manual and Stabilized
    # Home's altitude as a navigator that read this much high at arming took it.
    home_alt_error_m: float = 0.0
    range_max_m: float = 0.0  # a downward rangefinder reaching this far (0: none)

    def __post_init__(self) -> None:
        frame = load_airframe(self.airframe)
        self.has_brakes = frame.channel("brakes") is not None
        speed = frame.control.get("AIRSPEED_CRUISE", frame.cruise_speed_m_s)
        self.flight = Flight(frame.jsbsim_model, PHYSICS_HZ, Home(), self.airborne_agl_m, speed)
        self.flight.set_wind(*self.wind_ned)
        self.flight.set_turbulence(self.turbulence)
        decls = control_params(frame.control)
        values = {d.name: d.default for d in decls} | self.overrides
        self.controller = FlightController(flight_config(values), self.items)
        s = self.flight.state()
        self.status = VehicleStatus(mode=int(self.mode), armed=1, home_valid=1)
        self.status.home_lat_deg, self.status.home_lon_deg = s.lat_deg, s.lon_deg
        # Home is where the navigator is at arming: the resting aircraft, not the ground.
        airborne = bool(self.airborne_agl_m)
        self.status.home_alt_msl_m = s.alt_msl_m - s.alt_agl_m if airborne else s.alt_msl_m
        self.status.home_alt_msl_m += self.home_alt_error_m
        self.wheels_agl_m = 0.0 if airborne else s.alt_agl_m  # JSBSim's AGL is the CG's
        self.status.target_lat_deg = self.status.target_lon_deg = math.nan
        self.status.target_alt_msl_m = math.nan
        self.samples: list[Sample] = []
        self.reached: list[int] = []

    def nav(self) -> NavState:
        """The true state as a perfect navigator would publish it."""
        s = self.flight.state()
        nav = NavState(t_us=round(s.t_s * 1e6))
        nav.roll_rad, nav.pitch_rad, nav.yaw_rad = s.roll, s.pitch, s.yaw
        nav.roll_rate_rad_s, nav.pitch_rate_rad_s = s.p, s.q
        # Body yaw rate to earth heading rate is close enough for the yaw damper.
        nav.yaw_rate_rad_s = s.r
        nav.lat_deg, nav.lon_deg, nav.alt_msl_m = s.lat_deg, s.lon_deg, s.alt_msl_m
        nav.vn_m_s, nav.ve_m_s, nav.vd_m_s = s.vn, s.ve, s.vd
        nav.flags = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID)
        return nav

    def set_mode(self, mode: FlightMode) -> None:
        """Switch mode as the commander would (a new change count)."""
        self.status.mode = int(mode)
        self.status.changes += 1

    def run(self, seconds: float) -> None:
        """Fly on for ``seconds`` of simulation time."""
        steps = round(seconds * PHYSICS_HZ)
        for i in range(steps):
            if i % CONTROL_EVERY == 0:
                self._control()
            self.flight.step()

    def fly_until_disarmed(self, seconds: float) -> bool:
        """Fly until the controller disarms (True) or the simulation reaches ``seconds``."""
        while self.flight.t_s < seconds:
            self.run(1.0)
            if self.samples[-1].out.disarm:
                return True
        return False

    def _control(self) -> None:
        s = self.flight.state()
        if self.range_max_m > 0.0:
            self.controller.lander.range_reading = self._range(s)
        out = self.controller.step(self.nav(), self.status, s.t_s, self.sticks)
        self.reached += out.reached
        controls = {
            "aileron": out.aileron,
            "elevator": out.elevator,
            "rudder": out.rudder,
            "throttle": out.throttle,
            "flaps": out.flaps,
        }
        if self.has_brakes:
            controls["brakes"] = out.brakes
        self.flight.set_controls(controls)
        truth = (s.lat_deg, s.lon_deg, s.alt_msl_m, s.alt_agl_m, s.airspeed_m_s, s.roll, s.yaw)
        on_wheels = self.flight.weight_on_wheels()
        self.samples.append(Sample(s.t_s, *truth, out, (s.vn, s.ve, s.vd), on_wheels))

    def _range(self, s: object) -> RangeReading:
        """The true height along a body-down beam, valid within ``range_max_m``."""
        slant = s.alt_agl_m / max(math.cos(s.roll) * math.cos(s.pitch), 0.1)  # type: ignore[attr-defined]
        reading = RangeReading(t_us=round(s.t_s * 1e6), distance_m=slant)  # type: ignore[attr-defined]
        reading.max_distance_m = self.range_max_m
        reading.ground_clearance_m = self.wheels_agl_m  # read standing on the wheels
        reading.valid = int(0.0 < slant <= self.range_max_m)
        return reading

    def truth(self) -> dict[str, np.ndarray]:
        """The record as the columns of a truth file (those the scoring reads)."""
        cols = {"t": "t_s", "lat": "lat", "lon": "lon", "alt": "alt_msl", "roll": "roll"}
        out = {k: np.array([getattr(x, v) for x in self.samples]) for k, v in cols.items()}
        out["yaw"] = np.array([x.yaw for x in self.samples])
        for k, name in enumerate(("vn", "ve", "vd")):
            out[name] = np.array([x.vel_ned[k] for x in self.samples])
        out["on_wheels"] = np.array([float(x.on_wheels) for x in self.samples])
        return out


def mission(points: list[tuple[float, float]]) -> list[MissionItem]:
    """Take off eastwards, fly the points at 100 m, return home."""
    home = Home()
    frame = LocalFrame(home.lat_deg, home.lon_deg)
    rel = d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    items = []
    for cmd, (n, e) in [(d.MAV_CMD_NAV_TAKEOFF, (0.0, 600.0))] + [
        (d.MAV_CMD_NAV_WAYPOINT, p) for p in points
    ]:
        lat, lon = frame.latlon(n, e)
        p1 = 15.0 if cmd == d.MAV_CMD_NAV_TAKEOFF else 0.0
        x, y = round(lat * 1e7), round(lon * 1e7)
        items.append(MissionItem(len(items), rel, cmd, 0, 1, p1, 0, 0, 0, x, y, 100.0))
    rtl = d.MAV_CMD_NAV_RETURN_TO_LAUNCH
    items.append(MissionItem(len(items), rel, rtl, 0, 1, 0, 0, 0, 0, 0, 0, 0.0))
    return items
