"""Failsafes: what the vehicle does on its own when something it relies on goes away.

Pure: the time, the mode and what the link, the navigator and the fence say in; mode
changes and operator messages out (the ``vehicle.commander`` plug-in applies them).
As ArduPlane and PX4 do it:
- no ground-station heartbeat for ``FS_GCS_TIMEOUT`` while flying → Return; when the
  link comes back the mission is resumed if it was flying one and ``FS_GCS_RESUME`` is 1,
  unless the operator chose another mode meanwhile (a Return commanded over another link
  or on the mode switch stands);
- GPS lost (the navigator has had no usable fix for ``FS_GPS_LOST_S`` of its own sensor
  time) → the controller holds heading and height; when GPS has been steady again for
  ``FS_GPS_BACK_S`` the aircraft loiters where it is;
- outside the fence (or inside an exclusion zone) while flying → Return.
Each is announced once when it triggers and once when it clears. A failsafe that still
holds is acted on again when the operator changes the mode (as ArduPlane re-triggers its
fence action), unless the operator takes Manual or Stabilized: that is taking control.
The GPS is judged by the navigator's time stamps with hysteresis (``Hysteresis``), never
by one flag on one sample nor by how late a process ran, so it cannot flap; a navigator
aligning again (its process restarted in flight) is not a lost GPS for its first ten
seconds; a failsafe never fires on the ground or during a take-off roll (``flying`` is
false there).
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.control.modes import PILOT_MODES  # the operator flies
from companion.messages import FlightMode
from companion.messages.navigation import NAV_ALIGNING, NAV_DEAD_RECKONING, NAV_POSITION_VALID
from companion.params import ParamDecl
from mavlink_dialect import companion as d

FAILSAFE_PARAMS = (
    ParamDecl.switch("FS_GCS_ENABLE", 1.0, "return home when the ground station is lost"),
    ParamDecl("FS_GCS_TIMEOUT", 5.0, 1.0, 300.0, "s", "ground-station silence that counts as lost"),
    ParamDecl.switch("FS_GCS_RESUME", 1.0, "resume the mission when the link returns"),
    ParamDecl("FS_GPS_LOST_S", 1.0, 0.0, 60.0, "s", "no usable fix this long: GPS lost"),
    ParamDecl("FS_GPS_BACK_S", 3.0, 0.0, 60.0, "s", "good fixes this long: GPS back"),
    ParamDecl.switch("FENCE_ENABLE", 1.0, "return home when the fence is breached"),
)


@dataclass(frozen=True)
class Action:
    """A failsafe's decision: a mode to switch to (or None) and what to tell the operator."""

    mode: FlightMode | None
    text: str
    severity: int = d.MAV_SEVERITY_CRITICAL


class Hysteresis:
    """A bad/good condition judged over sensor time: bad only after ``lost_s`` with no good
    sample, good again only after ``back_s`` with no bad one.

    Samples are taken with their own time stamps; a sample older than the newest seen
    (a late process) says nothing new and is ignored. Whatever the flags do, the state
    can change at most once per hold time in each direction.
    """

    def __init__(self, lost_s: float, back_s: float) -> None:
        self.lost_us, self.back_us = round(lost_s * 1e6), round(back_s * 1e6)
        self.bad = False
        self.t_us: int | None = None  # the newest sample's time
        self.last_good_us: int | None = None
        self.good_since_us: int | None = None

    def update(self, t_us: int, good: bool) -> bool | None:
        """Take one sample; True when the condition just went bad, False when it just
        cleared, None when nothing changed."""
        if self.t_us is not None and t_us <= self.t_us:
            return None
        self.t_us = t_us
        if self.last_good_us is None:
            self.last_good_us = t_us  # the watch starts now: a hold time from here
        if not self.bad:
            if good:
                self.last_good_us = t_us
            elif t_us - self.last_good_us >= self.lost_us:
                self.bad, self.good_since_us = True, None
                return True
            return None
        if not good:
            self.good_since_us = None
            return None
        if self.good_since_us is None:
            self.good_since_us = t_us
        if t_us - self.good_since_us >= self.back_us:
            self.bad, self.last_good_us = False, t_us
            return False
        return None


@dataclass
class Situation:
    """What the failsafes look at, once per step."""

    now_us: int
    mode: FlightMode
    flying: bool  # armed and in the air
    gcs_silence_s: float  # since the last ground-station heartbeat; NaN: none heard yet
    nav_flags: int
    fence_breach: str | None
    nav_t_us: int | None = None  # the navigation solution's own time stamp


# A navigator restarted in the air aligns again from the GPS's course and the IMU; until it
# has, it publishes no position, which is not the GPS lost. Longer than this, it is.
ALIGN_GRACE_US = 10_000_000


class Failsafes:
    """Remembers which failsafes are active so each is announced once."""

    def __init__(self, params: dict[str, float]) -> None:
        self.params = params
        self.gcs_lost = self.gps_lost = self.fence_breached = False
        # What the link's return resumes: the mode the failsafe interrupted, or the one the
        # operator chose since (``operator_chose``).
        self.mode_before_gcs: FlightMode | None = None
        self.mode_seen: FlightMode | None = None  # the mode at the last step
        self.gps = Hysteresis(params["FS_GPS_LOST_S"], params["FS_GPS_BACK_S"])
        self.aligning_since_us: int | None = None

    def step(self, s: Situation) -> list[Action]:
        """The actions this situation calls for (usually none)."""
        changed = self.mode_seen is not None and s.mode != self.mode_seen
        actions = [*self._gcs(s), *self._gps(s), *self._fence(s)]
        if changed and not actions and s.flying and s.mode not in PILOT_MODES:
            actions = self._reassert(s.mode)
        self.mode_seen = s.mode
        return actions

    def operator_chose(self, mode: FlightMode) -> None:
        """The operator chose ``mode`` (a mode command accepted, the mode switch moved).
        While the ground station is lost that choice, not the mode the failsafe took over
        from, says whether the mission resumes when the link returns: a Return chosen
        while the failsafe returned home is kept."""
        if self.gcs_lost:
            self.mode_before_gcs = mode

    def _reassert(self, mode: FlightMode) -> list[Action]:
        """The operator chose another mode while a failsafe still holds: act on it again."""
        if self.fence_breached and mode != FlightMode.RTL:
            return [Action(FlightMode.RTL, "Fence still breached: returning home")]
        if self.gcs_lost and mode != FlightMode.RTL:
            return [Action(FlightMode.RTL, "Ground station still lost: returning home")]
        if self.gps_lost:  # the controller holds heading and height in every mode but Manual
            return [Action(None, "GPS still lost: holding heading and height")]
        return []

    def _gcs(self, s: Situation) -> list[Action]:
        p = self.params
        silent = s.gcs_silence_s > p["FS_GCS_TIMEOUT"]  # NaN (never heard) is not silence
        if not self.gcs_lost and silent and s.flying and p["FS_GCS_ENABLE"] >= 0.5:
            self.gcs_lost, self.mode_before_gcs = True, s.mode
            return [Action(FlightMode.RTL, "Failsafe: ground station lost, returning home")]
        if self.gcs_lost and not silent:
            self.gcs_lost = False
            resume = p["FS_GCS_RESUME"] >= 0.5 and self.mode_before_gcs == FlightMode.MISSION
            # Good news at NOTICE: QGroundControl shows CRITICAL and worse as a "Vehicle
            # Error" banner, which had announced the resumed mission as a fault.
            notice = d.MAV_SEVERITY_NOTICE
            if resume and s.mode == FlightMode.RTL and s.flying:
                back = "Ground station back: resuming the mission"
                return [Action(FlightMode.MISSION, back, notice)]
            return [Action(None, "Ground station back", notice)]
        return []

    def _gps(self, s: Situation) -> list[Action]:
        gps = self.gps
        gps.lost_us = round(self.params["FS_GPS_LOST_S"] * 1e6)
        gps.back_us = round(self.params["FS_GPS_BACK_S"] * 1e6)
        if s.nav_t_us is None or self._realigning(s):
            return []
        usable = not s.nav_flags & NAV_DEAD_RECKONING and s.nav_flags & NAV_POSITION_VALID
        gps.update(s.nav_t_us, bool(usable))
        # Lost while on the ground is said once airborne (arming checks should prevent it).
        if gps.bad and not self.gps_lost and s.flying:
            self.gps_lost = True
            return [Action(None, "Failsafe: GPS lost, holding heading and height")]
        if not gps.bad and self.gps_lost:
            self.gps_lost = False
            notice = d.MAV_SEVERITY_NOTICE
            if s.flying:
                return [Action(FlightMode.LOITER, "GPS back: loitering here", notice)]
            return [Action(None, "GPS back", notice)]
        return []

    def _realigning(self, s: Situation) -> bool:
        """A navigator that is aligning (restarted in flight: its first seconds) says
        nothing of the GPS; only one that stays so for ``ALIGN_GRACE_US`` counts as lost."""
        if not s.nav_flags & NAV_ALIGNING:
            self.aligning_since_us = None
            return False
        assert s.nav_t_us is not None
        if self.aligning_since_us is None:
            self.aligning_since_us = s.nav_t_us
        return s.nav_t_us - self.aligning_since_us < ALIGN_GRACE_US

    def _fence(self, s: Situation) -> list[Action]:
        enabled = self.params["FENCE_ENABLE"] >= 0.5
        if not self.fence_breached and s.fence_breach and s.flying and enabled:
            self.fence_breached = True
            return [Action(FlightMode.RTL, f"Fence breached ({s.fence_breach}): returning home")]
        if self.fence_breached and s.fence_breach is None:
            self.fence_breached = False
            return [Action(None, "Back inside the fence", d.MAV_SEVERITY_NOTICE)]
        return []
