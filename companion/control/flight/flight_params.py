"""Every gain, limit and speed of the flight controller, as ground-station parameters.

Names follow ArduPlane's where one exists, so a user of QGroundControl finds them. An
airframe file's ``[control]`` table changes the defaults (the same plans fly a Cessna or
a Cub by changing only that file); a value set from the ground station overrides both.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cached_property

from companion.control.flight.flare_aim import flare_run
from companion.control.laws.attitude import AttitudeGains
from companion.control.laws.tecs import TecsGains
from companion.control.mission.executor import ExecutorConfig
from companion.params import ParamDecl, declared_values


def _p(name: str, default: float, lo: float, hi: float, unit: str, doc: str) -> ParamDecl:
    return ParamDecl(name, default, lo, hi, unit, doc)


# Acro and Rattitude (control/flight/attitude_modes.py).
ACRO_PARAMS = (
    ParamDecl("ACRO_ROLL_RATE", 90.0, 10.0, 500.0, "deg/s", "Acro: roll rate at full stick"),
    ParamDecl("ACRO_PITCH_RATE", 45.0, 10.0, 500.0, "deg/s", "Acro: pitch rate at full stick"),
    ParamDecl("ACRO_PITCH_LIM", 60.0, 10.0, 85.0, "deg", "Acro: largest pitch either way"),
    ParamDecl("RATT_TH", 0.8, 0.0, 1.0, "norm",
              "Rattitude: stick deflection beyond which the sticks command rates"),
)  # fmt: skip


# The landing: glide, flare and rollout (control/flight/landing.py).
LANDING_PARAMS = (
    ParamDecl("LAND_FLARE_ALT", 3.0, 0.5, 20.0, "m", "landing: flare below this height"),
    ParamDecl("LAND_FLARE_SEC", 2.0, 0.5, 10.0, "s", "landing: flare this long before ground"),
    ParamDecl("LAND_TD_ALT", 0.0, 0.0, 2.0, "m", "landing: how far above where it rests the "
              "aircraft is when its wheels meet the runway in the flare (a tail dragger, tail up)"),
    ParamDecl("LAND_GA_HGT", 2.0, 0.0, 20.0, "m", "landing: go around when the flare is due "
              "this far above the glide path, and fly the approach again (0: off)"),
    ParamDecl("LAND_GA_LONG", 15.0, 0.0, 200.0, "m", "landing: go around from the flare's upper "
              "half when it would touch down over this far past the point (0: off)"),
    ParamDecl("LAND_GA_MAX", 2.0, 0.0, 10.0, "", "landing: most go-arounds of its own "
              "for one landing; then it lands from where it is"),
    ParamDecl("LAND_FLARE_AIM", 90.0, 50.0, 150.0, "%", "landing: the glide ends this share of "
              "the modelled flare's distance before the point (lower it if the airframe lands "
              "short: its flare then begins nearer the point)"),
    ParamDecl("LAND_FLARE_PWR", 4.0, 0.0, 10.0, "1/(m/s)", "landing: flare throttle per m/s "
              "sunk beyond what reaches the point, at most TRIM_THROTTLE (0: idle all flare)"),
    ParamDecl("LAND_FLARE_THR", 0.0, 0.0, 1.0, "", "landing: most throttle in the flare's "
              "lower half against a sink that lands short, as a lull gives (0: TRIM_THROTTLE)"),
    ParamDecl("LAND_FLOAT_SINK", 1.2, 0.0, 3.0, "m/s", "landing: a flare that would touch down "
              "over LAND_FLOAT_DIST past the point keeps sinking at up to this, no faster than "
              "its glide (0: off, the flare's sink falls to TECS_LAND_SINK whatever)"),
    ParamDecl("LAND_FLOAT_DIST", 10.0, 0.0, 50.0, "m", "landing: how far past the point a flare "
              "may float before it keeps sinking (LAND_FLOAT_SINK)"),
    ParamDecl("LAND_PITCH_CD", 0.0, -500.0, 1500.0, "cdeg", "landing: least pitch in the flare"),
    ParamDecl("LAND_FLARE_AOA", 0.0, 0.0, 15.0, "deg", "landing: wing's angle of attack over zero "
              "lift at TECS_LAND_ARSPD; faster, the flare's least pitch is lower (0: off)"),
    ParamDecl("LAND_DISARMDELAY", 3.0, 0.0, 127.0, "s", "landing: disarm this long after stop"),
    ParamDecl("TECS_LAND_ARSPD", 28.0, 5.0, 100.0, "m/s", "landing: approach airspeed"),
    ParamDecl("TECS_LAND_SINK", 0.4, 0.05, 2.0, "m/s", "landing: sink rate at touchdown"),
    ParamDecl("TECS_LAND_PMAX", 10.0, 0.0, 30.0, "deg", "landing: most pitch in the flare"),
    ParamDecl("LEVEL_ROLL_LIMIT", 5.0, 0.0, 45.0, "deg", "landing: most bank in the flare"),
    ParamDecl("LAND_SLOPE_MIN", 3.0, 1.0, 10.0, "deg", "landing: the least slope of the glide "
              "path; from a lower approach the height is held until the path is met"),
    ParamDecl("LAND_SLOPE_MAX", 0.0, 0.0, 20.0, "deg", "landing: a landing circle (LOITER_TO_ALT) "
              "descends below its height until the glide to the flare is no steeper (0: off)"),
    ParamDecl("TECS_APPR_SMAX", 0.0, 0.0, 20.0, "m/s", "landing: most sink on the approach, "
              "for a steep final or a tailwind (0: TECS_SINK_MAX)"),
    ParamDecl("TECS_LAND_SPDWGT", 0.0, 0.0, 2.0, "", "landing: TECS speed weight on the approach "
              "(0: pitch holds the glide path)"),
    ParamDecl("LAND_BRAKE", 0.5, 0.0, 1.0, "", "rollout: wheel brakes (fraction of full)"),
    ParamDecl("LAND_BRAKE_SPD", 50.0, 0.0, 50.0, "m/s", "rollout: brake below this ground speed"),
    ParamDecl("LAND_ROLL_ELEV", 0.0, 0.0, 1.0, "", "rollout: elevator held back once too slow "
              "to fly (a tail dragger pins its tail wheel); 0: the touchdown pitch is held"),
    ParamDecl("LAND_STEER_P", 8.0, 0.0, 10.0, "", "rollout: rudder per radian of heading error"),
    ParamDecl("LAND_FLAP_PERCNT", 0.0, 0.0, 100.0, "%", "landing: flaps on the approach"),
    ParamDecl("RTL_AUTOLAND", 0.0, 0.0, 2.0, "", "Return lands at DO_LAND_START: 1 after "
              "reaching home (or the rally point it flies to), 2 at once",
              values=((0.0, "Disabled"), (1.0, "After reaching home"), (2.0, "At once"))),
    ParamDecl.switch("RNGFND_LANDING", 1.0, "landing: flare on the rangefinder's height when "
                     "it has a fresh valid reading (no effect without one)"),
)  # fmt: skip


CONTROL_PARAMS = (
    _p("RLL_P", 1.0, 0.0, 5.0, "", "roll loop: aileron per radian of roll error"),
    _p("RLL_D", 0.1, 0.0, 2.0, "s", "roll loop: aileron per rad/s of roll rate"),
    _p("RLL_I", 0.2, 0.0, 2.0, "1/s", "roll loop: integrator gain"),
    _p("RLL_IMAX", 0.2, 0.0, 1.0, "", "roll loop: integrator limit (aileron fraction)"),
    _p("PTCH_P", 1.5, 0.0, 5.0, "", "pitch loop: elevator per radian of pitch error"),
    _p("PTCH_D", 0.2, 0.0, 2.0, "s", "pitch loop: elevator per rad/s of pitch rate"),
    _p("PTCH_I", 0.3, 0.0, 2.0, "1/s", "pitch loop: integrator gain"),
    _p("PTCH_IMAX", 0.3, 0.0, 1.0, "", "pitch loop: integrator limit (elevator fraction)"),
    # 0.5 left the c172p slipping up to 13° in and out of turns (5° p95): the heading then
    # reads as metres per second of wind along the track, and the roll-out weaves.
    _p("YAW_DAMP", 3.5, 0.0, 5.0, "s", "rudder per rad/s of yaw-rate error in a turn"),
    _p("SCALING_SPEED", 30.0, 5.0, 100.0, "m/s", "airspeed at which the loop gains apply as set"),
    _p("ROLL_LIMIT_DEG", 35.0, 5.0, 60.0, "deg", "largest bank angle"),
    ParamDecl.switch(
        "STALL_PREVENTION",
        1.0,
        "slow flight's stall margin: the bank limited to a level turn's load factor of at most "
        "(airspeed demand / AIRSPEED_MIN)², never under 35°, and the airspeed demand in a bank "
        "at least AIRSPEED_MIN × √(load factor) (0: off)",
    ),
    _p("PTCH_LIM_MAX_DEG", 20.0, 0.0, 45.0, "deg", "largest nose-up pitch"),
    _p("PTCH_LIM_MIN_DEG", -15.0, -45.0, 0.0, "deg", "largest nose-down pitch"),
    _p("NAVL1_PERIOD", 17.0, 5.0, 60.0, "s", "L1 guidance period: larger is gentler"),
    _p("NAVL1_DAMPING", 0.75, 0.5, 1.0, "", "L1 guidance damping"),
    _p("NAVL1_XTRACK_I", 0.02, 0.0, 0.1, "1/s", "L1 cross-track integrator gain"),
    _p("TECS_TIME_CONST", 5.0, 2.0, 20.0, "s", "height error → climb rate time constant"),
    _p("TECS_SPD_TC", 3.0, 1.0, 20.0, "s", "speed error → acceleration time constant"),
    _p("TECS_CLMB_MAX", 3.0, 0.5, 15.0, "m/s", "climb rate at full throttle"),
    _p("TECS_SINK_MAX", 3.0, 0.5, 15.0, "m/s", "sink rate at idle"),
    _p("TECS_THR_DAMP", 0.3, 0.0, 2.0, "", "throttle damping of the energy-rate error"),
    _p("TECS_PTCH_DAMP", 0.3, 0.0, 2.0, "", "pitch damping of the balance-rate error"),
    _p("TECS_INTEG_GAIN", 0.1, 0.0, 1.0, "", "energy integrators' gain"),
    _p("TECS_SPDWEIGHT", 1.0, 0.0, 2.0, "", "pitch looks after height (0), both (1), speed (2)"),
    _p("TRIM_THROTTLE", 0.6, 0.0, 1.0, "", "throttle for level flight at cruise speed"),
    _p("THR_MIN", 0.0, 0.0, 1.0, "", "least throttle in flight"),
    _p("THR_MAX", 1.0, 0.0, 1.0, "", "most throttle"),
    _p("AIRSPEED_CRUISE", 30.0, 5.0, 100.0, "m/s", "cruise airspeed"),
    _p("AIRSPEED_MIN", 25.0, 5.0, 100.0, "m/s", "least airspeed any speed demand gives"),
    _p("AIRSPEED_MAX", 45.0, 5.0, 120.0, "m/s", "most airspeed any speed demand gives"),
    _p("TKOFF_ROTATE_SPD", 27.0, 3.0, 60.0, "m/s", "take-off: airspeed at which to rotate"),
    _p("TKOFF_PITCH_DEG", 8.0, 0.0, 25.0, "deg", "take-off: pitch held after rotating"),
    _p("TKOFF_GND_PITCH", 0.0, -10.0, 20.0, "deg", "take-off: pitch held on the ground roll"),
    _p("TKOFF_STEER_P", 1.0, 0.0, 5.0, "", "take-off: rudder per radian of heading error"),
    _p(
        "TKOFF_TIMEOUT",
        0.0,
        0.0,
        120.0,
        "s",
        "take-off: abort (idle, brakes, disarm) when "
        "the roll is not at 4 m/s ground speed after this long (0: never)",
    ),
    _p("WP_RADIUS", 30.0, 1.0, 500.0, "m", "waypoint acceptance radius"),
    _p("WP_LOITER_RAD", 80.0, 10.0, 2000.0, "m", "loiter radius when an item gives none"),
    _p("RTL_ALT_M", 100.0, 10.0, 1000.0, "m", "return altitude above home"),
    _p(
        "RTL_LOITER_ALT_M",
        100.0,
        10.0,
        1000.0,
        "m",
        "height above home of the circle a return home ends in: the aircraft descends to it "
        "on arriving when it is below the return altitude, and never climbs to it",
    ),
    *LANDING_PARAMS,
    *ACRO_PARAMS,
)
BY_NAME = {p.name: p for p in CONTROL_PARAMS}
# STALL_PREVENTION never limits the bank to less. ArduPlane's 25° made a C172 at its
# approach speed (its AIRSPEED_MIN, flaps down: stalling near 23 m/s, 25 m/s at 35°) turn
# onto a 452 m final so wide that it landed 28 m beside the runway.
LEAST_BANK = math.radians(35.0)


def control_params(
    defaults: Mapping[str, float], origin: str = "airframe"
) -> tuple[ParamDecl, ...]:
    """The declarations with an airframe's defaults (``origin`` names the airframe, for
    ``companion params list``); unknown names raise KeyError."""
    unknown = sorted(set(defaults) - set(BY_NAME))
    if unknown:
        raise KeyError(f"unknown control parameter(s): {', '.join(unknown)}")
    return tuple(
        replace(p, default=float(defaults[p.name]), origin=origin) if p.name in defaults else p
        for p in CONTROL_PARAMS
    )


@dataclass(frozen=True)
class FlightConfig:
    """The parameter values, grouped the way the laws take them."""

    attitude: AttitudeGains
    tecs: TecsGains
    executor: ExecutorConfig
    values: Mapping[str, float]

    @cached_property  # read several times a step; a new config comes with new values
    def roll_limit(self) -> float:
        return math.radians(self.values["ROLL_LIMIT_DEG"])

    def bank_limit(self, airspeed: float) -> float:
        """``roll_limit``, less when flying slow (``STALL_PREVENTION``, as ArduPlane's),
        at the demanded ``airspeed`` (the measured one's gusts made a C172's turns in
        cruise wider): a C172 turning onto its final at its 30 m/s approach speed banked
        50°, slowed to 25 m/s in the turn and fell out of it into the ground."""
        if not self.values["STALL_PREVENTION"] or not math.isfinite(airspeed):
            return self.roll_limit
        load = (airspeed / max(self.values["AIRSPEED_MIN"], 1.0)) ** 2
        bank = math.acos(1.0 / load) if load > 1.0 else 0.0
        return min(self.roll_limit, max(bank, LEAST_BANK))

    def least_speed_in_turn(self, speed_min: float, roll: float) -> float:
        """``speed_min`` raised by the square root of the load factor of a level turn at
        ``roll`` (``STALL_PREVENTION``, as ArduPlane raises its energy controller's least
        airspeed): the stall speed rises so in a bank. Only slow flight feels it: the C172's
        45° at its 36 m/s cruise asks for 35.7 m/s, its 35° at 30 m/s for 33.1 m/s."""
        if not self.values["STALL_PREVENTION"]:
            return speed_min
        least = speed_min / math.sqrt(max(math.cos(roll), 0.25))
        return min(least, self.values["AIRSPEED_MAX"])

    def __getitem__(self, name: str) -> float:
        return self.values[name]


def flight_config(values: Mapping[str, float]) -> FlightConfig:
    """Group parameter values (name → value) for the controller."""
    v = declared_values(CONTROL_PARAMS, values)
    attitude = AttitudeGains(
        v["RLL_P"], v["RLL_D"], v["RLL_I"], v["RLL_IMAX"],
        v["PTCH_P"], v["PTCH_D"], v["PTCH_I"], v["PTCH_IMAX"],
        v["YAW_DAMP"], v["SCALING_SPEED"],
    )  # fmt: skip
    tecs = TecsGains(
        time_const=v["TECS_TIME_CONST"],
        speed_time_const=v["TECS_SPD_TC"],
        climb_max=v["TECS_CLMB_MAX"],
        sink_max=v["TECS_SINK_MAX"],
        throttle_trim=v["TRIM_THROTTLE"],
        throttle_min=v["THR_MIN"],
        throttle_max=v["THR_MAX"],
        throttle_damp=v["TECS_THR_DAMP"],
        integ_gain=v["TECS_INTEG_GAIN"],
        pitch_damp=v["TECS_PTCH_DAMP"],
        pitch_max=math.radians(v["PTCH_LIM_MAX_DEG"]),
        pitch_min=math.radians(v["PTCH_LIM_MIN_DEG"]),
        speed_weight=v["TECS_SPDWEIGHT"],
    )
    steepest = math.radians(v["LAND_SLOPE_MAX"])
    flare = flare_run(v["TECS_LAND_ARSPD"], math.tan(steepest), v)
    executor = ExecutorConfig(v["WP_RADIUS"], v["WP_LOITER_RAD"], v["RTL_ALT_M"], steepest, flare)
    return FlightConfig(attitude, tecs, executor, v)
