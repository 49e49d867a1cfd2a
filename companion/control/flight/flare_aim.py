"""The flare's sink demand that puts the wheels on the landing point.

The flare is an exponential approach to the ground: ḣ = -(s + h/τ), s the touchdown sink
rate (``TECS_LAND_SINK``). From height h it reaches the ground after

    T(τ) = τ · ln(1 + h / (s·τ)),

which grows with τ from 0 (a dive) to h/s (sinking at s all the way). Given the time the
aircraft needs to reach the landing point, the τ with T(τ) equal to it is the flare that
ends there, and s + h/τ its sink demand now. Solved afresh every step, the demand steers
the touchdown onto the point whatever put the aircraft where it is (a flare begun higher
or lower than planned, a gust, a slower or faster approach).

The time to the point counts the flare's loss of speed: with the throttle cut and the
nose coming up the aircraft slows (a C172 with flaps by 2-3 m/s in a 5 s flare, which
made it touch down 20-40 m short of where the constant-speed flare aimed), so the
deceleration is measured while flaring and the distance d is flown in the T that solves
d = v·T - a·T²/2.

A flare flown faster than the approach speed has lift to spare: at a given angle of attack
the wing lifts in proportion to V², so the attitude that lets the aircraft sink is lower
by the share ``1 - (V_a/V)²`` of the wing's angle of attack above zero lift at the
approach speed V_a (``LAND_FLARE_AOA``), and ``fast_pitch_drop`` takes that off the
flare's least pitch. A Cub 6 m/s fast after gusts at idle, held at its least pitch, rose
off its glide as the flare began and floated 48 m past the point at 0.1-1 m/s of sink.
Pure: numbers in, numbers out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from companion.control.laws.limits import clamp

MAX_DECEL = 3.0  # m/s²: more than any glider-like flare loses; a gust's spike is not speed lost
DECEL_TAU_S = 1.0  # the measured deceleration's smoothing
_ITERATIONS = 40
FLARE_SHARE_MAX = 0.5  # of a final: the glide before the flare keeps the rest
# Lift counted at most this many times the approach's: a faster reading is a gust's spike.
FAST_LIFT_MAX = 2.0


def time_to_point(distance: float, speed: float, decel: float) -> float:
    """Seconds to fly ``distance`` m starting at ``speed`` m/s, slowing by ``decel`` m/s²
    (inf when the aircraft would stop first; 0 when the point is behind)."""
    if distance <= 0.0:
        return 0.0
    speed = max(speed, 1.0)
    a = min(max(decel, 0.0), MAX_DECEL)
    if a < 1e-6:
        return distance / speed
    disc = speed * speed - 2.0 * a * distance
    if disc <= 0.0:
        return math.inf
    return (speed - math.sqrt(disc)) / a


def aimed_sink(height: float, t_go: float, touchdown_sink: float) -> float:
    """The sink rate now of the exponential flare from ``height`` that touches down after
    ``t_go`` s at ``touchdown_sink``: at least the touchdown sink (a point beyond reach is
    floated towards at it), inf when the point is passed or the aircraft is on it."""
    s = max(touchdown_sink, 1e-3)
    h = max(height, 0.0)
    if t_go <= 0.0:
        return math.inf
    ratio = t_go * s / max(h, 1e-6)  # T / (h/s): the fraction of the slowest flare's time
    if ratio >= 1.0:
        return s
    # With x = h/(s·τ): T = (h/s)·ln(1+x)/x, and ln(1+x)/x falls from 1 to 0 as x grows.
    lo, hi = 1e-6, 1e6
    for _ in range(_ITERATIONS):
        mid = math.sqrt(lo * hi)
        if math.log1p(mid) / mid > ratio:
            lo = mid
        else:
            hi = mid
    return s * (1.0 + math.sqrt(lo * hi))


def fast_pitch_drop(airspeed: float, approach_speed: float, aoa_deg: float) -> float:
    """How much lower (rad) the flare's least pitch may be at ``airspeed`` (m/s; NaN:
    unknown) than at ``approach_speed``, for a wing ``aoa_deg`` above its zero lift there:
    the share ``1 - (V_a/V)²`` of it that the extra speed's lift makes up (0 when slower,
    unknown or ``aoa_deg`` is 0)."""
    if aoa_deg <= 0.0 or not math.isfinite(airspeed) or airspeed <= approach_speed:
        return 0.0
    lift = min((airspeed / max(approach_speed, 1.0)) ** 2, FAST_LIFT_MAX)
    return math.radians(aoa_deg) * (1.0 - 1.0 / lift)


def least_flare_pitch(airspeed: float, v: Mapping[str, float]) -> float:
    """The flare's least pitch (rad) at ``airspeed``: ``LAND_PITCH_CD``, less
    ``fast_pitch_drop`` when faster than ``TECS_LAND_ARSPD`` (a floor set for the approach
    speed held a Cub 6 m/s fast at its least pitch, its nose above its glide's, and it
    floated 48 m long)."""
    drop = fast_pitch_drop(airspeed, v["TECS_LAND_ARSPD"], v["LAND_FLARE_AOA"])
    return math.radians(v["LAND_PITCH_CD"] / 100.0) - drop


def flare_pitch(pitch: float, airspeed: float, v: Mapping[str, float]) -> float:
    """``pitch`` (rad) within the flare's limits at ``airspeed``: ``TECS_LAND_PMAX`` above,
    ``least_flare_pitch`` below."""
    return clamp(pitch, least_flare_pitch(airspeed, v), math.radians(v["TECS_LAND_PMAX"]))


class DecelEstimate:
    """The aircraft's loss of speed along the runway, smoothed (m/s², + slowing)."""

    def __init__(self) -> None:
        self.decel = 0.0
        self._last: float | None = None

    def update(self, speed_along: float, dt: float) -> float:
        if self._last is not None and dt > 0.0:
            raw = (self._last - speed_along) / dt
            k = min(dt / DECEL_TAU_S, 1.0)
            self.decel += k * (min(max(raw, -MAX_DECEL), MAX_DECEL) - self.decel)
        self._last = speed_along
        return max(self.decel, 0.0)


def flare_run(ground_speed: float, slope: float, v: Mapping[str, float]) -> tuple[float, float]:
    """The flare from a glide of ``slope`` (rise over run) at ``ground_speed``: how far
    before touchdown it begins (m; on a final, at most ``FLARE_SHARE_MAX`` of it) and at
    what height (m).

    The exponential flare ḣ = -(s + h/τ) from height H at the glide's sink rate s0 has
    τ = H / (s0 - s) and lasts τ·ln(s0 / s). It begins where the landing begins it: at
    ``LAND_FLARE_ALT``, or higher on a path steep enough that ``LAND_FLARE_SEC`` of its
    sink comes first (the Cub at 4-5 m). The model's flare holds its speed and follows its
    demand at once; a real one slows with the throttle cut and lags the demand, so it
    flies a share of this distance, the airframe's ``LAND_FLARE_AIM`` (as ArduPlane's
    flare aim point)."""
    s_t = max(v["TECS_LAND_SINK"], 0.05)
    gs = max(ground_speed, 5.0)
    s0 = max(gs * slope, s_t * 1.5)
    h_f = max(v["LAND_FLARE_ALT"], v["LAND_FLARE_SEC"] * s0)
    tau = h_f / (s0 - s_t)
    return v["LAND_FLARE_AIM"] / 100.0 * gs * tau * math.log(s0 / s_t), h_f
