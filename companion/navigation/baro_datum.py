"""The barometer's datum for the INS: barometric height + offset = height in the frame.

The barometer is smooth over seconds but its zero drifts with weather and temperature;
GPS height is noisy but has no drift. So the INS's vertical channel follows the
barometer, and GPS pulls the offset towards itself with a time constant of minutes, but
only while the aircraft stands still on the ground. Moving (taxiing, flying) the datum
is held: a consumer receiver's height wanders by metres over minutes, and pulled along
with it the height above home (taken from the navigator's height at arming) moved with
it, so a landing's glide path lay metres high or low. ArduPilot (EKF3, height source
the barometer) and PX4 (EKF2, height reference the barometer) likewise keep the height
on the barometer in flight and let GPS height move no more than an origin.
"""

from __future__ import annotations

import math

# Consecutive readings this far apart are a new zero (the driver's process restarted and
# counts its relative height from where it is now), not a climb: 0.1 s apart, an aircraft
# moves a few metres up or down.
STEP_M = 30.0
# The INS found the aircraft standing still this recently: it is still on the ground (the
# still detector judges windows of a second).
STILL_RECENT_S = 2.5


class BaroDatum:
    """Holds the offset and how fresh the barometer is."""

    def __init__(self, interval_s: float, timeout_s: float, tau_s: float) -> None:
        self.interval_us = round(interval_s * 1e6)
        self.timeout_s = timeout_s
        self.tau_s = tau_s
        self.offset: float | None = None
        self.last_us: int | None = None
        self.last_m: float | None = None
        self.next_us = 0
        self.still_us: int | None = None  # when the aircraft was last found standing still

    def fresh(self, now_us: int) -> bool:
        """The barometer has spoken recently enough to be the height source."""
        return self.last_us is not None and (now_us - self.last_us) / 1e6 < self.timeout_s

    def due(self, t_us: int) -> bool:
        """Whether a reading at this time would be used (the rate limit)."""
        return t_us >= self.next_us

    def height(self, baro_m: float, t_us: int, ins_down: float) -> float | None:
        """The height measurement (metres up in the frame) for this reading, or None when
        it is not used (rate-limited or not a number)."""
        if not math.isfinite(baro_m) or t_us < self.next_us:
            return None
        self.next_us = t_us + self.interval_us
        if self.offset is None or not self.fresh(t_us):
            self.offset = -ins_down - baro_m  # (re)join where the INS height is now
        elif self.last_m is not None and abs(baro_m - self.last_m) > STEP_M:
            self.offset += self.last_m - baro_m  # a new zero: the height went on as it was
        self.last_us, self.last_m = t_us, baro_m
        return baro_m + self.offset

    def standing(self, t_us: int | None) -> None:
        """The INS found the aircraft standing still at this time (None: it has no time yet)."""
        if t_us is not None:
            self.still_us = t_us

    def follow_gps(self, gps_down: float, ins_down: float, t_us: int, last_us: int | None) -> None:
        """Standing on the ground, move the datum a little towards what GPS says the height
        is (for the time since the last fix, at ``last_us``); moving, leave it where it is."""
        still = self.still_us is not None and 0 <= t_us - self.still_us < STILL_RECENT_S * 1e6
        if self.offset is None or not math.isfinite(gps_down) or not still or last_us is None:
            return
        dt_s = max(t_us - last_us, 0) / 1e6
        self.offset += (ins_down - gps_down) * min(1.0, dt_s / self.tau_s)
