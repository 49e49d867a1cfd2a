"""The fixed-wing flight controller: mode → guidance target → energy and attitude → surfaces.

Pure: a navigation solution, the vehicle status and the time in; surface commands and what
NAV_CONTROLLER_OUTPUT / MISSION_CURRENT report out. The ``control.fixed_wing`` plug-in runs
it on the bus; tests and benchmarks run it against JSBSim directly."""

from __future__ import annotations

import math
from dataclasses import replace

from companion.control.flight.assisted import track_ahead
from companion.control.flight.attitude_modes import Sticks
from companion.control.flight.flight_params import FlightConfig
from companion.control.flight.landing import landing_flaps
from companion.control.flight.landing_flight import LandingFlight, MissionRef, Motion
from companion.control.flight.mode_targets import arrive, loiter_alt, mode_target, return_point
from companion.control.flight.on_ground import landed_now
from companion.control.flight.output import ControlOutput
from companion.control.flight.pilot_flight import PilotFlight
from companion.control.flight.speed_demand import CommandedSpeed, speed_demand
from companion.control.flight.takeoff import RunwayTakeoff
from companion.control.inputs import nav_usable, rates_or_zero, status_usable, sticks_usable
from companion.control.laws.attitude import AttitudeController
from companion.control.laws.l1_guidance import L1Guidance, LateralDemand, bank_for
from companion.control.laws.tecs import Tecs
from companion.control.laws.wind import WindEstimator
from companion.control.mission.executor import Kind, MissionExecutor, Setpoint
from companion.control.mission.items import MissionItem
from companion.control.mission.jump_counts import JumpCounts
from companion.control.mission.resume import start_mission
from companion.control.mission.set_current import MissionJumps
from companion.control.modes import PILOT_MODES
from companion.geodesy import STANDARD_GRAVITY as G
from companion.geodesy import LocalFrame
from companion.messages import FlightMode, NavState, TakeoffPhase, VehicleStatus
from companion.messages.navigation import NAV_DEAD_RECKONING

# An implicit take-off (a mission without one, started on the ground) climbs at least this
# high before it turns towards the first item: a take-off's wings-level climb-out and more.
IMPLICIT_TAKEOFF_AGL_M = 25.0
# Turns are planned at this fraction of the bank limit: the rest is for gusts and for
# the airspeed a turn gains or loses.
TURN_BANK_FRACTION = 0.7
MAX_TURN_WIND = 15.0  # m/s: a wind estimate beyond this is not trusted to size turns
# The mode of a status's number, without an enum call a step (status_usable has checked it).
_MODE_OF = {int(m): m for m in FlightMode}


class FlightController:
    """One aircraft's controller; ``step()`` once per navigation solution."""

    def __init__(self, config: FlightConfig, items: list[MissionItem] | None = None) -> None:
        self.items = list(items or [])
        self.config = config
        self.wind = WindEstimator()
        self.frame: LocalFrame | None = None
        self.home_alt = 0.0
        self.executor: MissionExecutor | None = None
        self.jumps = JumpCounts()  # DO_JUMP counts on disk: the plug-in gives it a folder
        self.takeoff: RunwayTakeoff | None = None
        self.go_arounds: int | None = None  # the commander's count when last seen
        self.set_currents = MissionJumps()  # MISSION_SET_CURRENT's, from the status
        self.landed: bool | None = None
        self.speed = CommandedSpeed()  # DO_CHANGE_SPEED's, from the status
        self.rejected = 0  # steps whose inputs were not usable (last good output kept)
        self._last_out = ControlOutput()
        self._last_t: float | None = None
        self._mode_key: tuple[int, int] | None = None
        self._mode_setpoint: Setpoint | None = None
        self._hold_course: Setpoint | None = None
        self._line: tuple[tuple[float, float], tuple[float, float]] | None = None
        self._corner_from: tuple[float, float] | None = None
        self.attitude = AttitudeController(config.attitude)
        self.tecs = Tecs(config.tecs)
        self.pilot = PilotFlight(self.attitude, self.tecs)
        self.lander = LandingFlight(self.attitude, self.tecs)
        self.l1 = L1Guidance(
            config["NAVL1_PERIOD"], config["NAVL1_DAMPING"], config["NAVL1_XTRACK_I"]
        )

    def set_config(self, config: FlightConfig) -> None:
        """New parameter values; the laws keep their integrators and memory."""
        self.config = config
        self.attitude.gains = config.attitude
        self.tecs.gains = config.tecs
        self.l1.period_s, self.l1.damping = config["NAVL1_PERIOD"], config["NAVL1_DAMPING"]
        self.l1.xtrack_i = config["NAVL1_XTRACK_I"]
        if self.executor is not None:
            self.executor.config = config.executor

    def set_mission(self, items: list[MissionItem]) -> None:
        """A new mission was stored: the next MISSION start uses it."""
        self.items = list(items)
        self.executor = None
        self.set_currents.forget()

    def _ensure_frame(self, nav: NavState, status: VehicleStatus) -> LocalFrame:
        if status.home_valid:
            home = (status.home_lat_deg, status.home_lon_deg, status.home_alt_msl_m)
        else:
            home = (nav.lat_deg, nav.lon_deg, nav.alt_msl_m)
        if self.frame is None or (self.frame.lat0, self.frame.lon0) != home[:2]:
            self.frame = LocalFrame(home[0], home[1])
            if self.executor is not None and not self.executor.finished:  # DO_SET_HOME's
                self.set_currents.pending = self.executor.current  # on from its own item
            self.executor, self._mode_key = None, None
        self.home_alt = home[2]
        return self.frame

    def step(
        self, nav: NavState, status: VehicleStatus, t_s: float, sticks: Sticks | None = None
    ) -> ControlOutput:
        """Surface commands for this navigation solution (and the pilot's ``sticks``, which
        fly Manual and Stabilized when given). Unusable inputs (``control.inputs``) are
        counted in ``rejected`` and the last good output kept: the laws never see them."""
        if not status.home_valid and (self.landed is None or self.landed):
            return ControlOutput()  # no home yet: nothing to fly from or back to
        usable = math.isfinite(t_s) and nav_usable(nav) and status_usable(status)
        if not (usable and sticks_usable(sticks)):
            self.rejected += 1
            return self._last_out.held()
        self._last_out = self._step(rates_or_zero(nav), status, t_s, sticks)
        return self._last_out

    def _step(
        self, nav: NavState, status: VehicleStatus, t_s: float, sticks: Sticks | None
    ) -> ControlOutput:
        dt = 0.0 if self._last_t is None else max(0.0, min(t_s - self._last_t, 0.2))
        self._last_t = t_s
        frame = self._ensure_frame(nav, status)
        pos = frame.ne(nav.lat_deg, nav.lon_deg)
        vel = (nav.vn_m_s, nav.ve_m_s)
        if self.landed:
            self.wind.on_ground(vel, nav.yaw_rad)
        else:
            self.wind.update(vel, nav.yaw_rad, dt)
        airspeed = self.wind.airspeed
        agl, least = nav.alt_msl_m - self.home_alt, self.config["AIRSPEED_MIN"]
        self.landed = landed_now(self.landed, agl, nav, airspeed, least)
        self.set_currents.see(status.mission_jumps, status.mission_jump_to)
        self.jumps.first_solution(bool(self.landed))  # before a mission takes them up
        out = ControlOutput(airspeed=airspeed, landed=bool(self.landed))
        out.brakes = self.config["LAND_BRAKE"] if self.landed else 0.0
        mode = _MODE_OF[status.mode] if status.mode else FlightMode.LOITER
        if mode in PILOT_MODES and sticks is not None:
            return self._fly_sticks(mode, sticks, (pos, vel, nav, airspeed, dt), out)
        if mode == FlightMode.MANUAL:
            out.throttle = self.config["TRIM_THROTTLE"] if not self.landed else 0.0
            return out
        setpoint = self._dead_reckoning(self._setpoint(mode, status, pos, nav, t_s, out), pos, nav)
        self.speed.follow(status.speed_m_s, self.executor)
        if setpoint is None:
            self.attitude.reset()
            return out  # on the ground with nothing that flies from there: idle
        self.tecs.gains = self.config.tecs
        if setpoint.kind == Kind.TAKEOFF or self._taking_off(nav):
            return self._fly_takeoff(setpoint, pos, nav, airspeed, dt, out)
        self.takeoff = None
        go_around = status.go_arounds != self.go_arounds
        self.go_arounds = status.go_arounds
        if setpoint.kind == Kind.LAND:
            motion, guidance = (pos, vel, nav, airspeed, dt), (self._fly, self._lateral)
            ex = self.executor
            return self.lander.fly(setpoint, motion, go_around, out, self.config, ex, guidance)
        self.lander.landing = None
        return self._fly(setpoint, pos, vel, nav, airspeed, dt, out)

    def _fly_sticks(
        self, mode: FlightMode, sticks: Sticks, motion: Motion, out: ControlOutput
    ) -> ControlOutput:
        key = (int(mode), -1)  # a pilot's mode is entered once, whatever the commands
        if key != self._mode_key:
            self.pilot.reset()
        self._mode_key = key
        return self.pilot.fly(mode, sticks, motion, out, self.config, bool(self.landed), self._fly)

    def _dead_reckoning(
        self, setpoint: Setpoint | None, pos: tuple[float, float], nav: NavState
    ) -> Setpoint | None:
        """Without GPS, hold the course and height the aircraft had when it was lost.

        Dead-reckoned positions drift, so following waypoints with them would steer by a
        growing error; a straight course at a known height is the safe thing until GPS
        returns (then the commander has the aircraft loiter)."""
        if not nav.flags & NAV_DEAD_RECKONING or self.landed:
            self._hold_course = None
            return setpoint
        if self._hold_course is None:
            alt = setpoint.alt_msl if setpoint is not None else nav.alt_msl_m
            self._hold_course = Setpoint(Kind.LINE, pos, track_ahead(pos, nav), alt)
        return self._hold_course

    def _taking_off(self, nav: NavState) -> bool:
        return self.takeoff is not None and self.takeoff.phase != TakeoffPhase.CLIMB_OUT

    def _setpoint(
        self,
        mode: FlightMode,
        status: VehicleStatus,
        pos: tuple[float, float],
        nav: NavState,
        t_s: float,
        out: ControlOutput,
    ) -> Setpoint | None:
        key = (int(mode), int(status.changes))
        entered = key != self._mode_key
        self._mode_key = key
        if self.lander.leave_home_landing(mode):
            self.executor = None
        if mode == FlightMode.MISSION:
            return self._mission(status, pos, nav, t_s, entered, out)
        if mode in (FlightMode.RTL, FlightMode.LAND) and (not self.landed or self.lander.landing):
            landing = self._mode_landing(mode, status, (pos, nav, t_s), entered, out)
            if landing is not None:
                return landing
        if self.landed and mode != FlightMode.TAKEOFF:
            return None
        if entered or self._mode_setpoint is None:
            home = (self.frame, self.home_alt)
            self._mode_setpoint = mode_target(mode, status, pos, nav, home, self.config)
        top = loiter_alt(status, self.home_alt, self.config)  # a return's circle at home
        self._mode_setpoint = arrive(
            self._mode_setpoint, mode, pos, nav.alt_msl_m, self.config, self._turn_radius(), top
        )
        return self._mode_setpoint

    def _mode_landing(
        self,
        mode: FlightMode,
        status: VehicleStatus,
        where: tuple[tuple[float, float], NavState, float],
        entered: bool,
        out: ControlOutput,
    ) -> Setpoint | None:
        """Return or Land flown as a landing (``LandingFlight.mode_landing``), else None."""
        pos, nav, t_s = where

        def fly_mission(ex: MissionExecutor) -> Setpoint | None:
            self.executor = ex
            return self._mission(status, pos, nav, t_s, False, out)

        back_to = return_point(status, self.frame)
        plan = MissionRef(self.items, self.frame, self.home_alt, self.executor, back_to)
        radius = self._turn_radius()
        sp = self.lander.mode_landing(mode, where, entered, plan, self.config, radius, fly_mission)
        self.executor = plan.executor
        return sp

    def _mission(
        self, status: VehicleStatus, pos: tuple[float, float], nav: NavState, t_s: float,
        entered: bool, out: ControlOutput,
    ) -> Setpoint | None:  # fmt: skip
        ex, resumed = self.executor, None
        # A set-current: a mission flown goes to its item now, with the leg from here.
        jump = self.set_currents.take(self.items) if status.mode == FlightMode.MISSION else None
        if ex is None or (entered and ex.finished) or jump is not None:
            assert self.frame is not None
            old, ex = (
                ex,
                MissionExecutor(  # what it says goes out with the landing's texts
                    self.items,
                    self.frame,
                    self.home_alt,
                    self.config.executor,
                    said=self.lander.said,
                ),
            )
            # In the air (a restarted controller, say) the leg is taken up as it was flown.
            radius = None if self.landed else self._turn_radius()
            first = status.mission_first if jump is None else jump
            resumed = start_mission(ex, first, pos, nav.alt_msl_m, radius)
            ex.jumps_done.update(self.jumps.take_up(self.items))  # restarted in the air
            if jump is not None and old is not None:  # DO_JUMP counts kept as they are
                ex.jumps_done.update(old.jumps_done)
            self.executor = ex
        setpoint = ex.step(pos, nav.alt_msl_m, t_s, self._turn_radius())
        if setpoint.kind in (Kind.LINE, Kind.CIRCLE) and ex.leads_to_landing():
            setpoint = replace(setpoint, approach=True)
        if resumed is not None:  # and the corner it may be turning through
            self._line = resumed.line_before(setpoint)
        if self.landed and setpoint.kind not in (Kind.TAKEOFF, Kind.LAND):
            if ex.finished:
                return None  # flown to its end: nothing more to take off for
            # No take-off item ahead on the ground (MAVSDK's mission plug-in adds none):
            # take off towards the item rather than sit armed and silent on the runway.
            ex.take_off_first(max(setpoint.alt_msl, self.home_alt + IMPLICIT_TAKEOFF_AGL_M))
            setpoint = ex.step(pos, nav.alt_msl_m, t_s, self._turn_radius())
        self.jumps.keep(self.items, ex.jumps_done)
        out.mission_seq = ex.current
        out.mission_finished = ex.finished
        out.reached = ex.drain_reached()
        out.servo_sets, out.passed_items = ex.take_actions()
        return setpoint

    def _fly_takeoff(
        self, setpoint: Setpoint, pos: tuple[float, float], nav: NavState, airspeed: float,
        dt: float, out: ControlOutput,
    ) -> ControlOutput:  # fmt: skip
        if self.takeoff is None:
            self.takeoff = RunwayTakeoff(pos, nav.yaw_rad, self.home_alt)
            # A take-off item flown in the air (a DO_JUMP back to it) climbs on its heading:
            # no runway there for Land to come back to.
            self.lander.runway = self.takeoff if self.landed else self.lander.runway
            self.attitude.reset()
        to = self.takeoff
        cfg = self.config.values
        speed = math.hypot(nav.vn_m_s, nav.ve_m_s)
        demand = to.step(pos, nav.alt_msl_m, nav.yaw_rad, nav.yaw_rate_rad_s, airspeed, cfg,
                         speed, dt)  # fmt: skip
        out.takeoff_phase = int(demand.phase)
        if demand.phase == TakeoffPhase.ABORTED:
            return to.abort(out, speed, cfg, self.lander.said)
        if demand.phase == TakeoffPhase.CLIMB_OUT:
            # Climb straight out along the runway with normal energy control.
            far = to.centreline_point(1e5)
            line = Setpoint(Kind.LINE, to.start, far, setpoint.alt_msl, speed=setpoint.speed)
            return self._fly(line, pos, (nav.vn_m_s, nav.ve_m_s), nav, airspeed, dt, out)
        ground = demand.phase == TakeoffPhase.GROUND_ROLL
        surfaces = self.attitude.step(
            demand.roll,
            demand.pitch,
            (nav.roll_rad, nav.pitch_rad),
            (nav.roll_rate_rad_s, nav.pitch_rate_rad_s, nav.yaw_rate_rad_s),
            max(airspeed, self.config["TKOFF_ROTATE_SPD"]),
            dt,
            integrate=not ground,
        )
        self.tecs.reset(demand.pitch)
        out.aileron, out.elevator = surfaces.aileron, surfaces.elevator
        out.rudder = demand.rudder
        out.throttle = demand.throttle
        out.brakes = 0.0
        out.nav_roll, out.nav_pitch = demand.roll, demand.pitch
        out.target_bearing = to.heading
        out.xtrack = to.xtrack(pos)
        out.alt_error = setpoint.alt_msl - nav.alt_msl_m
        return out

    def _fly(
        self, sp: Setpoint, pos: tuple[float, float], vel: tuple[float, float], nav: NavState,
        airspeed: float, dt: float, out: ControlOutput, least_speed: float = math.inf,
        climb_ff: float = 0.0, roll_dem: float = math.nan,
    ) -> ControlOutput:  # fmt: skip
        """Fly ``sp`` by the energy controller and the line guidance (or at ``roll_dem``)."""
        cfg = self.config
        speed_dem, speed_min = speed_demand(sp, self.speed.value, cfg.values, least_speed)
        if sp.approach:
            out.flaps = landing_flaps(cfg.values)
        lateral = self._lateral(sp, pos, vel, dt)
        if not math.isfinite(roll_dem):
            roll_dem = bank_for(lateral.lat_acc, cfg.bank_limit(speed_dem))
        # No stall in a turn, but for the take-off's climb and the landing, which fly their own.
        own = sp.approach or self.takeoff is not None or self.lander.landing is not None
        least = 0.0 if own else cfg.least_speed_in_turn(speed_min, roll_dem)
        speed_dem = max(speed_dem, least)
        energy = self.tecs.step(
            nav.alt_msl_m, -nav.vd_m_s, airspeed, sp.alt_msl, speed_dem, dt, climb_ff, least
        )
        surfaces = self.attitude.step(
            roll_dem,
            energy.pitch,
            (nav.roll_rad, nav.pitch_rad),
            (nav.roll_rate_rad_s, nav.pitch_rate_rad_s, nav.yaw_rate_rad_s),
            airspeed,
            dt,
        )
        out.aileron, out.elevator, out.rudder = surfaces.aileron, surfaces.elevator, surfaces.rudder
        out.throttle, out.brakes = energy.throttle, 0.0
        out.nav_roll, out.nav_pitch = roll_dem, energy.pitch
        out.target_bearing = lateral.target_bearing
        out.wp_dist = lateral.distance
        out.xtrack = lateral.xtrack
        out.alt_error = sp.alt_msl - nav.alt_msl_m
        out.aspd_error = speed_dem - airspeed
        return out

    def _turn_radius(self) -> float:
        """The radius of a turn at ``TURN_BANK_FRACTION`` of the bank limit at the fastest
        ground speed of the turn (cruise airspeed with the wind behind).

        From the planned speed and the slowly changing wind estimate, not the measured
        speed: a circle whose radius followed every gust would never be flown round."""
        wind = min(math.hypot(*self.wind.wind_ne), MAX_TURN_WIND)
        v = self.config["AIRSPEED_CRUISE"] + wind
        return v * v / (G * math.tan(self.config.roll_limit * TURN_BANK_FRACTION))

    def _lateral(
        self, sp: Setpoint, pos: tuple[float, float], vel: tuple[float, float], dt: float
    ) -> LateralDemand:
        if sp.kind == Kind.CIRCLE:
            # A circle tighter than the bank limit allows is flown at the tightest it can.
            radius = max(sp.radius, self._turn_radius())
            return self.l1.circle(pos, vel, sp.b, radius, sp.clockwise)
        line = (sp.a, sp.b)
        if line != self._line:
            # A leg that starts where the last one ended: its corner is flown as an arc.
            self._corner_from = self._line[0] if self._line and self._line[1] == sp.a else None
            self._line = line
        return self.l1.line(pos, vel, sp.a, sp.b, dt, self._corner_from, self._turn_radius())
