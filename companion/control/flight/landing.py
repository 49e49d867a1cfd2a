"""Automatic fixed-wing landing: approach, glide slope, flare, rollout, stop.

Pure: the aircraft's state and dt in, a demand out. The shape is the one ArduPlane and
PX4 publish for their fixed-wing landings, written here from their descriptions:

- **Approach**: the line from the previous waypoint through the touchdown point, at the
  landing airspeed (``TECS_LAND_ARSPD``), down a straight glide path from the previous
  waypoint's height. The path does not end at the touchdown point but where the flare
  must begin for the flare to end there, so the aircraft touches down on the target
  instead of floating past it.
- **Flare**: below ``LAND_FLARE_ALT`` above the runway, or when the ground is less than
  ``LAND_FLARE_SEC`` away at the present sink rate, the throttle is cut (power comes back
  only against a sink that would land short of the point, ``LAND_FLARE_PWR`` up to
  ``LAND_FLARE_THR``) and pitch flies an exponential flare: a sink-rate demand that falls
  with height towards ``TECS_LAND_SINK`` at the ground, from the sink rate at its start
  (the glide path's, when a gust has just slowed the sink below it) and from the glide's
  pitch and sink averaged over its last seconds (not a gust's moment). A flare that would
  float well past the point on that shape keeps sinking instead, at up to its starting
  sink and ``LAND_FLOAT_SINK``, towards a touchdown near the point. Bank is limited to
  ``LEVEL_ROLL_LIMIT``; the crab is kept, so a crosswind does not drift the aircraft off
  the centreline in the flare.
- **Rollout**: on the wheels the rudder (and the steered wheel) holds the centreline,
  the wings are held level, the throttle is idle (the brakes come on with it).
- **Stopped**: slower than a walking pace for ``LAND_DISARMDELAY`` seconds: disarm.
- **Go-around** (``abort()``): full climb power, climb straight out along the runway.
  Also of itself, while ``may_go_around``, when the flare is due with the aircraft more
  than ``LAND_GA_HGT`` above the glide path: an approach that a gust has left that high
  floats far past the point (a pilot's unstabilized approach), so it is flown again.
  And in the flare's upper half, when even sinking at the most the flare asks for it would
  touch down more than ``LAND_GA_LONG`` past the point (a balloon in rising air).

Heights are above the touchdown point's altitude, from the navigator's altitude (which
fuses the barometer and GPS), less ``LAND_TD_ALT`` (a tail dragger's wheels meet the runway
tail up, its centre higher than where it rested at arming); the flare (when to begin it,
its sink demand, the touchdown) takes the rangefinder's height instead whenever the state
carries one (``range_height.py``: valid, fresh, wings near level), as ArduPlane's
``RNGFND_LANDING``.
Once the rangefinder reaches the ground on the approach, it also corrects where the
navigator's altitude puts the runway (``ground_alt``), as ArduPlane's rangefinder
correction does: the touchdown point's altitude is home's, taken from the navigator at
arming, and a GPS-aided height that read 3 m high then (and is right by the landing) laid
the glide path 3 m too high, and the Cub touched down 40 m long.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from companion.control.flight.flare_aim import (
    FLARE_SHARE_MAX,
    DecelEstimate,
    aimed_sink,
    flare_pitch,
    flare_run,
    least_flare_pitch,
    time_to_point,
)
from companion.control.flight.landing_io import AircraftState, LandingDemand, Point
from companion.control.laws.limits import clamp
from companion.geodesy import wrap_pi
from companion.messages.control import LandPhase

# On the wheels: this low and no longer sinking for a moment. The flare sinks at least at
# TECS_LAND_SINK until then, so a navigator a few decimetres out still touches down
# gently instead of dropping the last of the height with the flare given up.
TOUCHDOWN_AGL_M = 1.0
TOUCHDOWN_CLIMB = -0.15  # m/s
TOUCHDOWN_S = 0.3
STEER_LOOKAHEAD_M = 20.0
STOPPED_SPEED = 0.8  # m/s: slower than this counts as stopped
# On the wheels the nose is lowered this much from the touchdown attitude: the wing stops
# lifting (a tricycle puts its nose wheel down, a tail dragger holds its main wheels on),
# so a gust cannot lift the aircraft back off while it is still fast.
WHEELS_DOWN_PITCH = math.radians(3.0)
NOT_FLYING = 0.6  # below this fraction of the approach speed the wings cannot lift it
# The flare's sink demand may aim for the point within these fractions of the nominal
# flare's: more, and a flare that started early floats then drops onto the runway.
# Never more than the nominal: a flare that dives for a point it would float past reaches
# the ground before its pitch has caught up (short and hard); long is the lesser harm.
AIM_LOW, AIM_HIGH = 0.6, 1.0
# But a flare whose nominal shape would touch down more than LAND_FLOAT_DIST past the point
# asks for the sink of the flare that touches down there, at most the sink it began from
# (never steeper than the glide it came from, so the pitch has nothing to catch up) and
# LAND_FLOAT_SINK (a firm touchdown, not a hard one): Cubs that gusts held up at idle
# followed the nominal flare's falling demand and floated 16-32 m long.
# The runway's altitude follows the rangefinder's ground with this time constant: a few
# readings' noise is smoothed, and the glide path moves down no faster than it can be flown.
GROUND_TAU_S = 1.5
GROUND_CORRECTION_MAX_M = 10.0  # a ground further from the runway's is not the runway
SINK_P = 0.10  # rad of pitch per m/s of sink-rate error in the flare
SINK_I = 0.05  # rad per (m/s·s)
# The flare starts from the glide's pitch and sink averaged over this long, not from the
# moment's: a gust that had just pitched the nose down or changed the sink is not the trim.
GLIDE_TRIM_TAU_S = 2.0
FLARE_THR_SHARE = 0.5  # LAND_FLARE_THR below this share of the flare's planned height
COMMITTED = 0.5  # below this share of the flare's planned height it lands, floating or not


class Landing:
    """One landing, from the previous waypoint ``start`` to the touchdown point."""

    def __init__(
        self, start: Point, start_alt_msl: float, touchdown: Point, land_alt_msl: float
    ) -> None:
        self.start, self.touchdown = start, touchdown
        self.start_alt, self.land_alt = start_alt_msl, land_alt_msl
        self.ground_alt = land_alt_msl  # the runway as the navigator's altitude reads it
        dn, de = touchdown[0] - start[0], touchdown[1] - start[1]
        self.length = max(math.hypot(dn, de), 1.0)
        self.heading = math.atan2(de, dn)
        self.unit = (math.cos(self.heading), math.sin(self.heading))
        self.phase = LandPhase.APPROACH
        self._flare_integ = 0.0
        self._flare_pitch = math.nan  # the glide's smoothed pitch until the flare
        self._flare_sink = math.nan  # and its smoothed sink
        self._level_s = 0.0
        self._stopped_s = 0.0
        self._touchdown_pitch = 0.0
        self._tau = 1.0
        self._sink0 = 0.0  # m/s: the sink rate the flare began from
        self._glide_sink = 0.0  # m/s: the glide path's sink rate at the last approach step
        self.flare_alt = math.nan  # where the flare is planned to begin (flare_distance)
        self._decel = DecelEstimate()
        self.may_go_around = False  # the caller allows a go-around of the landing's own
        self.high_at_flare = math.nan  # m above the glide path when it went around so
        self.long_at_flare = math.nan  # m past the point it would have touched down, so

    # -- geometry --------------------------------------------------------------------

    def along(self, pos: Point) -> float:
        """Metres past the touchdown point along the approach (negative before it)."""
        return (pos[0] - self.touchdown[0]) * self.unit[0] + (
            pos[1] - self.touchdown[1]
        ) * self.unit[1]

    def speed_along(self, vel: Point) -> float:
        """The ground speed along the approach (m/s, negative when flying back)."""
        return vel[0] * self.unit[0] + vel[1] * self.unit[1]

    def xtrack(self, pos: Point) -> float:
        """Metres right of the centreline."""
        dn, de = pos[0] - self.touchdown[0], pos[1] - self.touchdown[1]
        return -dn * self.unit[1] + de * self.unit[0]

    def point(self, along: float) -> Point:
        """The centreline point ``along`` metres past the touchdown point."""
        return (
            self.touchdown[0] + along * self.unit[0],
            self.touchdown[1] + along * self.unit[1],
        )

    def flare_distance(self, ground_speed: float, v: Mapping[str, float]) -> float:
        """How far before touchdown the flare begins at this ground speed (``flare_run``):
        the glide's sink rate is the ground speed times the slope, which itself depends on
        where the flare begins, so the two are solved together by a few fixed-point steps.
        """
        dist, h_f = 0.0, v["LAND_FLARE_ALT"]
        for _ in range(4):
            run, h_f = flare_run(ground_speed, self._slope(dist, h_f, v), v)
            dist = min(run, FLARE_SHARE_MAX * self.length)
        self.flare_alt = h_f
        return dist

    def _slope(self, flare_dist: float, flare_alt: float, v: Mapping[str, float]) -> float:
        # Never flatter than LAND_SLOPE_MIN: on a flatter path the flare starts from so
        # little sink that it is planned long, and a C172 at idle in it sank short of the
        # point (15-50 m on 1.3-2.2° finals). The path then starts below the approach's
        # height, which the aircraft holds until it meets the path, as on a glide slope.
        drop = self.start_alt - self._wheels_alt(v) - flare_alt
        least = math.tan(math.radians(v["LAND_SLOPE_MIN"]))
        return max(drop / max(self.length - flare_dist, 1.0), least)

    def glide_alt(self, pos: Point, flare_dist: float, v: Mapping[str, float]) -> float:
        """The glide path's height (MSL) abeam ``pos``."""
        h_f = self.flare_alt if math.isfinite(self.flare_alt) else v["LAND_FLARE_ALT"]
        to_flare = -self.along(pos) - flare_dist
        alt = self._wheels_alt(v) + h_f + to_flare * self._slope(flare_dist, h_f, v)
        return min(alt, max(self.start_alt, self._wheels_alt(v) + h_f))

    def _wheels_alt(self, v: Mapping[str, float]) -> float:
        """The height (MSL) the navigator reads when the wheels meet the runway in the
        flare's attitude: the runway's, plus ``LAND_TD_ALT`` (a tail dragger lands tail up,
        its centre higher than where it rests on its tail wheel)."""
        return self.ground_alt + v["LAND_TD_ALT"]

    def _correct_ground(self, s: AircraftState, dt: float) -> None:
        """Move ``ground_alt`` towards the ground the rangefinder finds under the aircraft."""
        found = s.alt_msl - s.range_height
        if not math.isfinite(found) or abs(found - self.land_alt) > GROUND_CORRECTION_MAX_M:
            return
        self.ground_alt += (found - self.ground_alt) * min(dt / GROUND_TAU_S, 1.0)

    # -- the phases ------------------------------------------------------------------

    def abort(self) -> None:
        """Go around: climb out along the runway (the caller decides what comes next)."""
        if self.phase in (LandPhase.APPROACH, LandPhase.FLARE):
            self.phase = LandPhase.GO_AROUND

    def step(self, s: AircraftState, v: Mapping[str, float], dt: float) -> LandingDemand:
        """The demand for this step; ``v`` holds the parameters by name."""
        ground_rate = 0.0  # m/s: how fast the rangefinder moves the runway's altitude
        if self.phase == LandPhase.APPROACH:
            ground_before = self.ground_alt
            self._correct_ground(s, dt)
            ground_rate = (self.ground_alt - ground_before) / dt if dt > 0 else 0.0
            self._smooth_trim(s, dt)
        raw = s.range_height if math.isfinite(s.range_height) else s.alt_msl - self.ground_alt
        height = raw - v["LAND_TD_ALT"]  # above the wheels' touchdown
        ground_speed = math.hypot(*s.vel)
        due = self.phase == LandPhase.APPROACH and self._flare_due(height, s.climb_rate, v)
        if due:
            self._go_around_if_high(s.pos, height, ground_speed, v)
        if due and self.phase == LandPhase.APPROACH:
            self._begin_flare(height, s.climb_rate, v)
        # On the wheels: low and no longer sinking, or slower than anything that flies.
        slow = ground_speed < 0.5 * v["TECS_LAND_ARSPD"]
        level = height < TOUCHDOWN_AGL_M and s.climb_rate > TOUCHDOWN_CLIMB
        self._level_s = self._level_s + dt if level and self.phase == LandPhase.FLARE else 0.0
        if self.phase == LandPhase.FLARE and (self._level_s >= TOUCHDOWN_S or slow):
            self.phase = LandPhase.ROLLOUT
            self._touchdown_pitch = s.pitch - WHEELS_DOWN_PITCH
        if self.phase in (LandPhase.ROLLOUT, LandPhase.STOPPED):
            return self._rollout(s, ground_speed, v, dt)
        if self.phase == LandPhase.FLARE:
            self._go_around_if_long(s, height, v)  # it may go around instead
        if self.phase == LandPhase.FLARE:
            return self._flare(s, height, v, dt)
        line = (self.start, self.point(1e4))
        if self.phase == LandPhase.GO_AROUND:
            alt = max(self.start_alt, self.land_alt + 30.0)
            return LandingDemand(self.phase, line, alt, v["AIRSPEED_CRUISE"])
        flare_dist = self.flare_distance(ground_speed, v)
        alt = self.glide_alt(s.pos, flare_dist, v)
        on_slope = alt < self.start_alt
        speed_along = self.speed_along(s.vel)
        slope = self._slope(flare_dist, self.flare_alt, v)
        self._glide_sink = max(speed_along, 0.0) * slope
        # The path moves with the runway's height as the rangefinder corrects it, and the
        # energy controller follows the path's rate, not only its slope's.
        ff = ground_rate - self._glide_sink if on_slope else 0.0
        return LandingDemand(
            self.phase, line, alt, v["TECS_LAND_ARSPD"], flaps=landing_flaps(v), climb_ff=ff
        )

    def _begin_flare(self, height: float, climb_rate: float, v: Mapping[str, float]) -> None:
        self.phase = LandPhase.FLARE
        self._flare_integ = 0.0
        self._decel = DecelEstimate()
        # The flare's time constant makes its first sink demand the sink rate now, or the
        # glide's when a gust has just slowed the sink: a flare slower than the one planned
        # (flare_distance) floated, and a C172 touched down 47 m long.
        s_t = max(v["TECS_LAND_SINK"], 0.05)
        self._sink0 = max(-climb_rate, self._glide_sink)
        self._tau = max(height, 0.5) / max(self._sink0 - s_t, 0.3)

    def _smooth_trim(self, s: AircraftState, dt: float) -> None:
        if not math.isfinite(self._flare_pitch):
            self._flare_pitch, self._flare_sink = s.pitch, -s.climb_rate
        k = min(dt / GLIDE_TRIM_TAU_S, 1.0)
        self._flare_pitch += (s.pitch - self._flare_pitch) * k
        self._flare_sink += (-s.climb_rate - self._flare_sink) * k

    def _go_around_if_high(
        self, pos: Point, height: float, ground_speed: float, v: Mapping[str, float]
    ) -> None:
        """Go around when the flare is due this far above the glide path. Over 96 random
        plans the laws' landings began their flares within 1.5 m of the path, except
        two Cubs in gusts, 2.8 and 3.2 m above it, which touched down 15 and 20 m long;
        the whole vehicle's Cub on random plan 3, 3.9 m above it, 37.6 m long."""
        limit = v["LAND_GA_HGT"]
        if not self.may_go_around or limit <= 0.0:
            return  # the path's height is not worked out: it would land either way
        path = self.glide_alt(pos, self.flare_distance(ground_speed, v), v) - self._wheels_alt(v)
        if height - path > limit:
            self.high_at_flare = height - path
            self.phase = LandPhase.GO_AROUND

    def _go_around_if_long(self, s: AircraftState, height: float, v: Mapping[str, float]) -> None:
        """Go around from the flare's upper half when, even sinking at the most the flare
        asks for (its starting sink, ``LAND_FLOAT_SINK``), the aircraft would touch down
        more than ``LAND_GA_LONG`` past the point: rising air held a C172's flare at 4 m
        for 50 m (its least pitch above its glide's), and it touched down 41.8 m long."""
        limit = v["LAND_GA_LONG"]
        if not self.may_go_around or limit <= 0.0 or not height >= COMMITTED * self.flare_alt:
            return  # lower, it lands whatever: a climb begun there could touch down first
        speed_along = self.speed_along(s.vel)
        most = min(self._sink0, v["LAND_FLOAT_SINK"] or self._sink0)
        sink = max(most, -s.climb_rate, 0.1)
        along = self.along(s.pos)
        if height > sink * time_to_point(limit - along, speed_along, self._decel.decel):
            self.long_at_flare = along + max(speed_along, 0.0) * height / sink
            self.phase = LandPhase.GO_AROUND

    def _flare_due(self, height: float, climb_rate: float, v: Mapping[str, float]) -> bool:
        sink = max(-climb_rate, 0.1)
        return height < v["LAND_FLARE_ALT"] or height / sink < v["LAND_FLARE_SEC"]

    def _flare(
        self, s: AircraftState, height: float, v: Mapping[str, float], dt: float
    ) -> LandingDemand:
        s_t = max(v["TECS_LAND_SINK"], 0.05)
        nominal = s_t + max(height, 0.0) / self._tau
        # Steer the touchdown onto the point: the flare that ends there (flare_aim.py),
        # counting the speed it loses, kept near the nominal flare's so the touchdown
        # stays gentle either way.
        speed_along = self.speed_along(s.vel)
        decel = self._decel.update(speed_along, dt)
        t_go = time_to_point(-self.along(s.pos), speed_along, decel)
        aim = aimed_sink(height, t_go, s_t)
        t_float = time_to_point(v["LAND_FLOAT_DIST"] - self.along(s.pos), speed_along, decel)
        floating = min(aimed_sink(height, t_float, s_t), self._sink0, v["LAND_FLOAT_SINK"])
        # Already sinking faster than that (a lull), it is asked less, down to the nominal
        # flare's sink at twice it: a C172 asked to keep 1.2 m/s as a lull sank it at 2 m/s
        # pitched up too late and touched down 18 m short.
        floating = min(floating, 2.0 * floating + s.climb_rate)
        sink_dem = clamp(aim, AIM_LOW * nominal, max(AIM_HIGH * nominal, floating))
        error = -s.climb_rate - sink_dem  # + when sinking faster than wanted: pitch up
        # The pitch lags the demand, and at idle with flaps a C172 sinks 4-5 m/s: a flare
        # begun in a gust's dive stayed above its sink demand all the way and touched down
        # 26 m short. Power holds it up, but only against a sink that lands short of the
        # point: one begun late and high floats past it as it is. Below half the flare's
        # height, its pitch up, as much as a pilot gives in gusts (LAND_FLARE_THR): at
        # TRIM_THROTTLE a lull there sank a C172 15 m short; higher, more only sped it up.
        short = -s.climb_rate - max(aim, sink_dem)
        low = height < FLARE_THR_SHARE * self.flare_alt
        most = (v["LAND_FLARE_THR"] if low else 0.0) or v["TRIM_THROTTLE"]
        throttle = clamp(v["LAND_FLARE_PWR"] * short, 0.0, most)
        self._flare_integ = clamp(self._flare_integ + SINK_I * error * dt, -0.1, 0.25)
        # The flight path the sink demand asks for, on top of the glide's pitch: the change
        # of path angle is the pitch change to first order (the feedback does the rest).
        speed = max(math.hypot(*s.vel), 5.0)
        path_change = (self._flare_sink - sink_dem) / speed
        if low and error > 0.0:
            # Sinking too fast low in the flare, it pitches up from its least pitch, not from
            # a fast steep glide's far below it: from a tailwind final's -10° its demand
            # stayed under the least pitch down to 1 m, the sink at 1.3 m/s, and a C172
            # touched down 19.7 m short.
            least = least_flare_pitch(s.airspeed, v)
            self._flare_pitch = max(self._flare_pitch, least - path_change)
        pitch = self._flare_pitch + path_change + SINK_P * error + self._flare_integ
        return LandingDemand(
            self.phase,
            (self.start, self.point(1e4)),
            self.land_alt,
            v["TECS_LAND_ARSPD"],
            pitch=flare_pitch(pitch, s.airspeed, v),  # faster, a lower floor (flare_aim.py)
            throttle=throttle,
            roll_limit=math.radians(v["LEVEL_ROLL_LIMIT"]),
            flaps=landing_flaps(v),
        )

    def _rollout(
        self, s: AircraftState, ground_speed: float, v: Mapping[str, float], dt: float
    ) -> LandingDemand:
        # Steer for a point ahead on the centreline, as on the take-off roll.
        heading_dem = self.heading - math.atan2(self.xtrack(s.pos), STEER_LOOKAHEAD_M)
        rudder = v["LAND_STEER_P"] * wrap_pi(heading_dem - s.yaw) - 0.3 * s.yaw_rate
        self._stopped_s = self._stopped_s + dt if ground_speed < STOPPED_SPEED else 0.0
        slow = ground_speed < NOT_FLYING * v["TECS_LAND_ARSPD"]
        stopped = self._stopped_s > 0.0
        disarm = False
        if stopped:
            self.phase = LandPhase.STOPPED
            disarm = self._stopped_s >= v["LAND_DISARMDELAY"]
        return LandingDemand(
            self.phase,
            (self.start, self.point(1e4)),
            self.land_alt,
            0.0,
            pitch=self._touchdown_pitch,
            throttle=0.0,
            rudder=clamp(rudder, -1.0, 1.0),
            elevator=v["LAND_ROLL_ELEV"] if v["LAND_ROLL_ELEV"] > 0.0 and slow else math.nan,
            brakes=v["LAND_BRAKE"] if ground_speed < v["LAND_BRAKE_SPD"] or stopped else 0.0,
            roll_limit=0.0,
            disarm=disarm,
            flaps=landing_flaps(v),
        )


def landing_flaps(v: Mapping[str, float]) -> float:
    """The flaps of the landing (0 up .. 1 fully down), from ``LAND_FLAP_PERCNT``."""
    return clamp(v["LAND_FLAP_PERCNT"] / 100.0, 0.0, 1.0)
