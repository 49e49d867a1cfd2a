"""Slow flight keeps its stall margin in the turns (``STALL_PREVENTION``, the energy
controller's underspeed protection).

A plan that slows the C172 to its least airspeed (DO_CHANGE_SPEED 30 m/s) and reverses
course round a DO_JUMP loop, in a 5 m/s crosswind with light turbulence: with the speed
demand at 30 m/s in a 35° bank (the stall speed about 10 % higher than level) and pitch
holding the height at full throttle, one gust sequence took the aircraft from 100 m to 2.7 m
above the ground mid-mission. ArduPlane raises its least airspeed by the square root of the
turn's load factor, and every TECS gives height up for speed once the throttle can do no
more; so does this one now.
"""

from __future__ import annotations

import math

from companion.control.flight.flight_params import flight_config
from companion.control.laws.tecs import Tecs, TecsGains
from mavlink_dialect import companion as d
from tests.support.closed_loop import ClosedLoop
from tests.unit.control.mission.executor_flying import item, jump, speed, wp

SLOW = 30.0944645885553  # the C172's AIRSPEED_MIN and a little more, as the plan had it
ITEMS = [
    item(0, d.MAV_CMD_NAV_TAKEOFF, (0.0, 300.0), z=100.0, p1=15.0),
    speed(1, SLOW),
    wp(2, (1_261.5, -10.9), z=117.0),
    wp(3, (-691.0, 1_220.9), z=119.6),
    jump(4, 0, 2),  # back to the take-off item (met in the air), twice
    wp(5, (456.7, 775.5), z=100.0),
]
CROSSWIND = (1.298, 4.829, 0.0)  # m/s north, east: 5 m/s across the plan's runway (345°)


def test_a_slow_loop_in_gusts_keeps_its_height():
    loop = ClosedLoop("c172p", ITEMS, wind_ned=CROSSWIND, turbulence="light")
    loop.flight.fdm["atmosphere/randomseed"] = 24  # the gusts that took it down to 2.7 m
    loop.run(60.0)  # the take-off and the climb
    start = len(loop.samples)
    for _ in range(120):
        loop.run(5.0)
        if loop.samples[-1].out.mission_seq == 5:
            break
    assert loop.reached == [0, 2, 3, 0, 2, 3, 0, 2, 3], loop.reached
    lowest = min(s.alt_agl for s in loop.samples[start:])
    assert lowest > 80.0, f"down to {lowest:.1f} m above the ground in the loop"


def test_the_least_airspeed_rises_with_the_bank():
    config = flight_config({"AIRSPEED_MIN": 30.0, "AIRSPEED_MAX": 50.0})
    assert config.least_speed_in_turn(30.0, 0.0) == 30.0
    assert math.isclose(config.least_speed_in_turn(30.0, math.radians(35.0)), 33.15, abs_tol=0.01)
    assert config.least_speed_in_turn(30.0, math.radians(89.0)) == 50.0  # AIRSPEED_MAX
    off = flight_config({"AIRSPEED_MIN": 30.0, "STALL_PREVENTION": 0.0})
    assert off.least_speed_in_turn(30.0, math.radians(35.0)) == 30.0


def test_under_the_least_airspeed_at_full_throttle_pitch_gives_up_height_for_speed():
    tecs = Tecs(TecsGains())
    # 100 m below the demanded height and 3 m/s under the least airspeed (30 m/s): the
    # throttle opens, then the nose comes down for the speed, not up for the height.
    first = tecs.step(100.0, 0.0, 26.5, 200.0, 30.0, 0.02, least_speed=30.0)
    assert first.throttle == 1.0 and not tecs.underspeed  # the throttle had not opened yet
    pitch = [tecs.step(100.0, 0.0, 26.5, 200.0, 30.0, 0.02, least_speed=30.0) for _ in range(50)]
    assert tecs.underspeed and all(p.throttle == 1.0 for p in pitch)
    # Without the protection the same state holds the nose level, between height and speed;
    # with it, the nose goes down as far as it may (PTCH_LIM_MIN_DEG) for the speed.
    plain = Tecs(TecsGains())
    held = [plain.step(100.0, 0.0, 26.5, 200.0, 30.0, 0.02) for _ in range(51)]
    assert abs(held[-1].pitch) < 0.05 and pitch[-1].pitch == TecsGains().pitch_min
    # Back at the least airspeed: height counts again.
    tecs.step(100.0, 0.0, 30.5, 200.0, 30.0, 0.02, least_speed=30.0)
    assert not tecs.underspeed
