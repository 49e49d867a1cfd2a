"""DO_CHANGE_SPEED as the controller flies it: the commanded airspeed, within the
airframe's limits, until the commander forgets it; the latest of it and a mission's own
DO_CHANGE_SPEED wins (``companion.control.flight.speed_demand``)."""

from __future__ import annotations

import math
import statistics

from companion.control.flight.flight_params import flight_config
from companion.control.flight.speed_demand import CommandedSpeed, speed_demand
from companion.control.mission.executor import Kind, Setpoint
from companion.control.mission.items import change_speed
from companion.geodesy import LocalFrame
from companion.messages import FlightMode
from mavlink_dialect import companion as d
from tests.support.closed_loop import ClosedLoop
from tests.unit.control.mission.executor_flying import executor, item, speed, wp

LINE = Setpoint(Kind.LINE, (0.0, 0.0), (1000.0, 0.0), 100.0)
LIMITS = {"AIRSPEED_CRUISE": 36.0, "AIRSPEED_MIN": 30.0, "AIRSPEED_MAX": 50.0,
          "TECS_LAND_ARSPD": 28.0}  # fmt: skip


def _airspeeds(loop: ClosedLoop, seconds: float) -> tuple[float, float]:
    """The mean true airspeed of the last ``seconds``, and the controller's estimate of it
    (from GPS and its wind estimate: this aircraft has no airspeed sensor)."""
    last = [s for s in loop.samples if s.t_s >= loop.flight.t_s - seconds]
    return statistics.fmean(s.airspeed for s in last), statistics.fmean(
        s.out.airspeed for s in last
    )


def test_the_c172_flies_the_commanded_airspeed_and_the_cruise_again_once_it_is_forgotten():
    loop = ClosedLoop("c172p", [], mode=FlightMode.GUIDED, airborne_agl_m=300.0)
    s = loop.flight.state()
    lat, lon = LocalFrame(s.lat_deg, s.lon_deg).latlon(40_000.0, 0.0)  # straight on north
    status = loop.status
    status.target_lat_deg, status.target_lon_deg, status.target_alt_msl_m = lat, lon, s.alt_msl_m
    loop.run(50.0)
    cruise, cruise_est = _airspeeds(loop, 15.0)
    assert abs(cruise_est - 36.0) < 1.0, cruise_est  # AIRSPEED_CRUISE
    status.speed_m_s = 45.0  # MAVSDK's set_current_speed(45), as the commander says it
    loop.run(50.0)
    fast, fast_est = _airspeeds(loop, 15.0)
    assert abs(fast_est - 45.0) < 1.0, fast_est
    # The air flown through: 9 m/s faster too (the still air's estimate is some 2.5 m/s
    # under the truth at both speeds: the wind estimate's, not the demand's).
    assert abs((fast - cruise) - 9.0) < 1.5, (cruise, fast)
    status.speed_m_s = math.nan  # a change of mode: the commander forgot it
    loop.run(50.0)
    _, again_est = _airspeeds(loop, 15.0)
    assert abs(again_est - 36.0) < 1.0, again_est


def test_the_demand_is_the_setpoints_then_the_commanded_then_the_cruise_within_limits():
    assert speed_demand(LINE, math.nan, LIMITS)[0] == 36.0
    assert speed_demand(LINE, 42.0, LIMITS)[0] == 42.0
    assert (
        speed_demand(Setpoint(Kind.LINE, (0, 0), (1, 0), 100.0, speed=33.0), 42.0, LIMITS)[0]
        == 33.0
    )  # a mission's own speed, set after the command
    assert speed_demand(LINE, 80.0, LIMITS)[0] == 50.0  # AIRSPEED_MAX, whatever comes
    approach = Setpoint(Kind.LINE, (0, 0), (1, 0), 100.0, approach=True)
    assert speed_demand(approach, 45.0, LIMITS) == (28.0, 28.0)  # the approach's own


def test_a_new_command_overrides_the_missions_speed_until_its_next_change():
    ex = executor([speed(0, 32.0), wp(1, (2000.0, 0.0))])
    ex.step((0.0, 0.0), 180.0, 0.0)
    assert ex.speed == 32.0
    commanded = CommandedSpeed()
    commanded.follow(0.0, ex)  # a status without one (0: none)
    assert math.isnan(commanded.value) and ex.speed == 32.0
    commanded.follow(44.0, ex)
    assert commanded.value == 44.0 and math.isnan(ex.speed)  # the command, flown now
    ex.speed = 34.0  # the mission's next DO_CHANGE_SPEED
    commanded.follow(44.0, ex)  # the same command again is no news
    assert ex.speed == 34.0
    commanded.follow(math.nan, ex)  # forgotten: the mission's own stays
    assert math.isnan(commanded.value) and ex.speed == 34.0


def test_a_mission_items_speed_change_follows_the_spec():
    def after(p1: float, p2: float, before: float = 30.0) -> float:
        return change_speed(item(0, d.MAV_CMD_DO_CHANGE_SPEED, p1=p1, p2=p2), before)

    assert after(0, 40.0) == 40.0 and after(1, 40.0) == 40.0  # airspeed, ground speed
    assert after(0, -1) == 30.0  # no change (it had gone back to the cruise)
    assert math.isnan(after(0, -2)) and math.isnan(after(0, 0))  # the default
    assert after(2, 5.0) == 30.0 and after(3, 5.0) == 30.0  # climb, descent: not a speed
    assert after(math.nan, 40.0) == 30.0


def test_the_flight_config_limits_are_the_ones_bounding_it():
    cfg = flight_config({"AIRSPEED_MIN": 30.0, "AIRSPEED_MAX": 50.0})
    assert speed_demand(LINE, 10.0, cfg.values)[0] == 30.0
