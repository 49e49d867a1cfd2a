"""How the flight controller flies a landing: the glide by the energy controller, the flare
and rollout by attitude, a go-around and its second approach, Return ending in a landing
(ArduPlane's ``RTL_AUTOLAND``), and Land without a landing in the mission (``home_landing``).

A collaborator of ``FlightController``, given the attitude and energy controllers it
shares and, per step, the parameters, the mission and the controller's guidance; the
landing itself is ``Landing`` (landing.py).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from companion.control.flight.landing import Landing
from companion.control.flight.landing_io import AircraftState, LandingDemand
from companion.control.flight.landing_pattern import (
    HOME_TOUCHDOWN_M,
    Approach,
    choose_pattern,
    go_around_run,
    least_approach,
)
from companion.control.flight.range_height import range_height
from companion.control.laws.l1_guidance import bank_for
from companion.control.mission.executor import Kind, MissionExecutor, Setpoint
from companion.control.mission.items import NAV_COMMANDS, MissionItem
from companion.messages import FlightMode, LandPhase, NavState, RangeReading
from mavlink_dialect import companion as d

if TYPE_CHECKING:
    from companion.control.flight.flight_params import FlightConfig
    from companion.control.flight.output import ControlOutput
    from companion.control.flight.takeoff import RunwayTakeoff
    from companion.control.laws.attitude import AttitudeController
    from companion.control.laws.l1_guidance import LateralDemand
    from companion.control.laws.tecs import Tecs
    from companion.control.mission.fence import Fence
    from companion.geodesy import LocalFrame

FLARE_PITCH_GAIN = 2.5
GO_AROUND_MARGIN_M = 5.0  # this close to the go-around height: come round again


def land_start(items: list[MissionItem]) -> int | None:
    """The first DO_LAND_START's index (where a Return that lands joins the mission)."""
    return next((k for k, it in enumerate(items) if it.command == d.MAV_CMD_DO_LAND_START), None)


def approach_start(items: list[MissionItem], land_index: int) -> int:
    """Where a second approach to the NAV_LAND at ``land_index`` begins: its DO_LAND_START,
    else the item flown to before it (not a region of interest's place)."""
    for k in range(land_index - 1, -1, -1):
        if items[k].command == d.MAV_CMD_DO_LAND_START:
            return k
    for k in range(land_index - 1, -1, -1):
        if items[k].command in NAV_COMMANDS and (items[k].x or items[k].y):
            return k
    return land_index


@dataclass
class MissionRef:
    """The controller's stored mission and its executor, lent for one step: a landing may
    replace ``executor`` (the controller takes it back after)."""

    items: list[MissionItem]
    frame: LocalFrame | None
    home_alt: float
    executor: MissionExecutor | None
    returns_to: tuple[float, float] = (0.0, 0.0)  # where Return flies: home, or a rally point


Motion = tuple[tuple[float, float], tuple[float, float], NavState, float, float]
"""Position and velocity (local N, E), the navigation solution, the airspeed, the step."""
FlyLine = Callable[..., "ControlOutput"]  # FlightController._fly
Lateral = Callable[[Setpoint, tuple[float, float], tuple[float, float], float], "LateralDemand"]


class LandingFlight:
    """The landing half of the flight controller (see the module's docstring)."""

    def __init__(self, attitude: AttitudeController, tecs: Tecs) -> None:
        self.attitude = attitude
        self.tecs = tecs
        self.landing: Landing | None = None
        # The rangefinder's newest reading, set by whoever steps the controller (None: none).
        self.range_reading: RangeReading | None = None
        self.range_steps = 0  # landing steps that flew on the rangefinder's height
        self.runway: RunwayTakeoff | None = None  # this flight's take-off roll, kept after
        self.landing_home = False  # the executor flies ``_home_landing``'s, not the mission
        self.return_lands = False  # this Return ends in the mission's landing
        self.fence: Fence | None = None  # the stored geofence: Land's own pattern keeps inside
        self.refused = False  # no pattern fits in the fence: this Land circles instead
        self.said: list[tuple[int, str]] = []  # (MAV_SEVERITY, text) for the operator
        # The landing's own go-arounds (LAND_GA_HGT, LAND_GA_LONG) so far, and the touchdown
        # they count for.
        self.own_go_arounds: tuple[tuple[float, float, float], int] = ((0.0, 0.0, 0.0), 0)

    def fly(
        self,
        sp: Setpoint,
        motion: Motion,
        go_around: bool,
        out: ControlOutput,
        config: FlightConfig,
        executor: MissionExecutor | None,
        guidance: tuple[FlyLine, Lateral],
    ) -> ControlOutput:
        """Fly the landing ``sp``; ``go_around``: the commander counted a new go-around."""
        pos, _, nav, airspeed, dt = motion
        fly_line, lateral = guidance
        land = self.landing
        if land is None or (land.start, land.touchdown, land.land_alt) != (sp.a, sp.b, sp.alt_msl):
            from_alt = sp.from_alt if math.isfinite(sp.from_alt) else nav.alt_msl_m
            land = self.landing = Landing(sp.a, from_alt, sp.b, sp.alt_msl)
        if go_around:
            land.abort()
        land.may_go_around = self._own_go_arounds_left(sp, config)
        vel = (nav.vn_m_s, nav.ve_m_s)
        agl = range_height(self.range_reading, nav.t_us, nav.roll_rad, nav.pitch_rad,
                           config["RNGFND_LANDING"])  # fmt: skip
        self.range_steps += math.isfinite(agl)
        state = AircraftState(pos, vel, nav.alt_msl_m, -nav.vd_m_s, nav.pitch_rad, nav.yaw_rad,
                              nav.yaw_rate_rad_s, agl, airspeed)  # fmt: skip
        dem = land.step(state, config.values, dt)
        if math.isfinite(land.high_at_flare) or math.isfinite(land.long_at_flare):
            self._went_around(land, config)  # of itself: said once
        out.land_phase = int(dem.phase)
        out.flaps, out.brakes = dem.flaps, dem.brakes
        if dem.phase == LandPhase.GO_AROUND and nav.alt_msl_m >= dem.alt_msl - GO_AROUND_MARGIN_M:
            self._come_round(executor, pos, nav.alt_msl_m)
        if dem.phase in (LandPhase.APPROACH, LandPhase.GO_AROUND):
            line = Setpoint(Kind.LINE, dem.line[0], dem.line[1], dem.alt_msl, speed=dem.speed)
            if dem.phase == LandPhase.APPROACH:  # the glide path before the speed
                weight = config["TECS_LAND_SPDWGT"]
                sink = config["TECS_APPR_SMAX"] or config.tecs.sink_max
                self.tecs.gains = replace(config.tecs, speed_weight=weight, sink_max=sink)
            return fly_line(line, pos, vel, nav, airspeed, dt, out, dem.speed, dem.climb_ff)
        if dem.disarm and executor is not None and not self.landing_home:
            executor.land_complete()
            out.mission_finished = True
            out.reached += executor.drain_reached()
        out.disarm = dem.disarm
        return self._fly_attitude(dem, (pos, vel, nav, airspeed, dt), out, config, lateral)

    def _own_go_arounds_left(self, sp: Setpoint, config: FlightConfig) -> bool:
        """Whether this landing may still go around of itself (LAND_GA_MAX): counted per
        touchdown point, so a second approach to it counts on."""
        key = (sp.b[0], sp.b[1], sp.alt_msl)
        if key != self.own_go_arounds[0]:
            self.own_go_arounds = (key, 0)
        return self.own_go_arounds[1] < config["LAND_GA_MAX"]

    def _went_around(self, land: Landing, config: FlightConfig) -> None:
        key, count = self.own_go_arounds
        self.own_go_arounds = (key, count + 1)
        # One STATUSTEXT (50 characters): "Land: 3.9 m high at the flare: going around 1/2",
        # "Land: would land 42 m long: going around 1/2".
        if math.isfinite(land.high_at_flare):
            why = f"{land.high_at_flare:.1f} m high at the flare"
        else:
            why = f"would land {min(land.long_at_flare, 999.0):.0f} m long"
        land.high_at_flare = land.long_at_flare = math.nan
        text = f"Land: {why}: going around {count + 1}/{config['LAND_GA_MAX']:.0f}"
        self.said.append((d.MAV_SEVERITY_WARNING, text))

    def _come_round(self, ex: MissionExecutor | None, pos: tuple[float, float], alt: float) -> None:
        """Climbed out after a go-around: fly the landing's approach again. The DO_JUMPs
        keep their counts: a jump on the way from the approach's start (NAV_LAND straight
        after a loop's DO_JUMP) has done its repeats, and sent the aircraft round the whole
        loop again when counted afresh."""
        if ex is not None:
            done = dict(ex.jumps_done)
            ex.start(approach_start(ex.items, ex.current), pos, alt)
            ex.jumps_done.update(done)
        self.landing = None

    def _fly_attitude(
        self,
        dem: LandingDemand,
        motion: Motion,
        out: ControlOutput,
        config: FlightConfig,
        lateral_of: Lateral,
    ) -> ControlOutput:
        """The flare and the rollout: pitch and throttle given, bank limited, L1 on the
        centreline for what bank is allowed."""
        pos, vel, nav, airspeed, dt = motion
        line = Setpoint(Kind.LINE, dem.line[0], dem.line[1], dem.alt_msl)
        lateral = lateral_of(line, pos, vel, dt)
        roll_dem = bank_for(lateral.lat_acc, min(dem.roll_limit, config.roll_limit))
        flying = dem.phase == LandPhase.FLARE
        # The flare's pitch changes in a second or two, faster than cruise ever asks for:
        # the pitch loop works harder while flaring (the gains return after). Its integrator
        # too: as the aircraft slows the elevator the pitch needs grows, and at the cruise
        # rate the pitch stayed 2-3 degrees under the demand, sinking faster than the flare.
        gains = self.attitude.gains
        if flying:
            self.attitude.gains = replace(
                gains,
                pitch_p=gains.pitch_p * FLARE_PITCH_GAIN,
                pitch_i=gains.pitch_i * FLARE_PITCH_GAIN,
            )
        surfaces = self.attitude.step(
            roll_dem,
            dem.pitch,
            (nav.roll_rad, nav.pitch_rad),
            (nav.roll_rate_rad_s, nav.pitch_rate_rad_s, nav.yaw_rate_rad_s),
            max(airspeed, config["TKOFF_ROTATE_SPD"] * 0.5),
            dt,
            integrate=flying,
        )
        self.attitude.gains = gains
        self.tecs.reset(dem.pitch)
        out.aileron, out.elevator = surfaces.aileron, surfaces.elevator
        if math.isfinite(dem.elevator):
            out.elevator = dem.elevator
        out.rudder = dem.rudder if math.isfinite(dem.rudder) else surfaces.rudder
        out.throttle = dem.throttle
        out.nav_roll, out.nav_pitch = roll_dem, dem.pitch
        out.target_bearing = lateral.target_bearing
        out.xtrack = lateral.xtrack
        out.alt_error = dem.alt_msl - nav.alt_msl_m
        return out

    def mode_landing(
        self,
        mode: FlightMode,
        where: tuple[tuple[float, float], NavState, float],
        entered: bool,
        plan: MissionRef,
        config: FlightConfig,
        turn_radius: float,
        fly_mission: Callable[[MissionExecutor], Setpoint | None],
    ) -> Setpoint | None:
        """The mission's landing from its first DO_LAND_START, None when not landing now.
        Land (PX4's Land, as a fixed wing flies it): at once. Return with RTL_AUTOLAND: 2
        at once, 1 once home (or the rally point it flies to) is reached (as ArduPlane).
        ``where``: position, navigation solution, time; ``fly_mission`` steps the
        controller's mission on this executor."""
        pos, nav, t_s = where
        first = land_start(plan.items)
        if first is None and mode == FlightMode.LAND:
            return self._land_at_home(pos, nav, t_s, plan, config, turn_radius)
        autoland = 2 if mode == FlightMode.LAND else round(config["RTL_AUTOLAND"])
        if first is None or autoland not in (1, 2):
            return None
        if entered:
            self.return_lands = autoland == 2
        if not self.return_lands:
            back = plan.returns_to
            reach = max(config["WP_LOITER_RAD"], turn_radius) * 1.5
            if math.hypot(pos[0] - back[0], pos[1] - back[1]) > reach:
                return None
            self.return_lands = True
        if entered or plan.executor is None or plan.executor.current < first:
            assert plan.frame is not None
            ex = MissionExecutor(
                plan.items, plan.frame, plan.home_alt, config.executor, said=self.said
            )
            ex.start(first, pos, nav.alt_msl_m)
            plan.executor = ex
        return fly_mission(plan.executor)

    def _land_at_home(
        self,
        pos: tuple[float, float],
        nav: NavState,
        t_s: float,
        plan: MissionRef,
        config: FlightConfig,
        turn_radius: float,
    ) -> Setpoint | None:
        """Land (MAVSDK's land(), MAV_CMD_NAV_LAND without a position) with no landing in
        the mission: back onto the runway of this flight's take-off, along its roll; without
        one (started in the air), straight in from here to home. PX4 loiters down where the
        aircraft is; a fixed wing with wheels needs a runway, and this one is known. The
        pattern keeps inside the fence (landing_pattern.py); when none does, None: the
        controller circles where the aircraft is, as Land entered without a pattern."""
        if self.refused:
            return None
        if not self.landing_home or plan.executor is None:
            assert plan.frame is not None
            items = self._home_landing(pos, nav.yaw_rad, plan.frame, config, turn_radius)
            if items is None:
                return None
            ex = MissionExecutor(items, plan.frame, plan.home_alt, config.executor, said=self.said)
            ex.start(0, pos, nav.alt_msl_m)
            plan.executor, self.landing_home, self.landing = ex, True, None
        sp = plan.executor.step(pos, nav.alt_msl_m, t_s, turn_radius)
        plan.executor.drain_reached()  # not the stored mission's items: nothing to report
        return sp

    def _home_landing(
        self,
        pos: tuple[float, float],
        yaw: float,
        frame: LocalFrame,
        config: FlightConfig,
        turn_radius: float,
    ) -> list[MissionItem] | None:
        """The pattern's items, or None (said why) when none fits inside the fence."""
        if self.runway is not None:
            base, heading = self.runway.start, self.runway.heading
        elif math.hypot(*pos) > HOME_TOUCHDOWN_M:
            base, heading = (0.0, 0.0), math.atan2(-pos[1], -pos[0])
        else:
            base, heading = (0.0, 0.0), yaw
        fence = self.fence

        def keeps(a: tuple[float, float], b: tuple[float, float], width: float) -> bool:
            if fence is None or fence.empty:
                return True
            return fence.keeps(frame.latlon(*a), frame.latlon(*b), width)

        least = least_approach(config.values)
        approach = Approach(pos, go_around_run(config.values))
        pattern = choose_pattern(base, heading, keeps, least, turn_radius, approach)
        if pattern is None:
            self.refused = True
            self.said.append((d.MAV_SEVERITY_CRITICAL, "Land: no pattern fits the fence, circling"))
            return None
        # Said with or without a fence: the ground station shows no pattern it did not plan.
        self.said.append((d.MAV_SEVERITY_NOTICE, pattern.described()))
        if fence is not None and not fence.empty:
            if not pattern.leg_kept:
                self.said.append(
                    (d.MAV_SEVERITY_WARNING, "Land: the way to the loiter crosses the fence")
                )
            elif not pattern.around_kept:
                self.said.append(
                    (d.MAV_SEVERITY_WARNING, "Land: a go-around would cross the fence")
                )
        return pattern.items(frame)

    def leave_home_landing(self, mode: FlightMode) -> bool:
        """Another mode: True when the controller is to drop the executor (the stored
        mission's is made afresh when it is flown)."""
        if mode != FlightMode.LAND:
            self.refused = False
        if self.landing_home and mode != FlightMode.LAND:
            self.landing_home = False
            return True
        return False
