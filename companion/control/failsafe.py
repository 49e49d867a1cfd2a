"""Failsafes: what the vehicle does on its own when something it relies on goes away.

Pure: the time, the mode and what the link, the navigator and the fence say in; mode
changes and operator messages out (the ``vehicle.commander`` plug-in applies them).
As ArduPlane and PX4 do it:
- no ground-station heartbeat for ``FS_GCS_TIMEOUT`` while flying → Return; when the
  link comes back the mission is resumed if it was flying one and ``FS_GCS_RESUME`` is 1;
- GPS lost (the navigator dead-reckons) → the controller holds heading and height; when
  GPS is back the aircraft loiters where it is;
- outside the fence (or inside an exclusion zone) while flying → Return.
Each is announced once when it triggers and once when it clears.
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.messages import FlightMode, NavFlags
from companion.params import ParamDecl
from mavlink_dialect import companion as d

FAILSAFE_PARAMS = (
    ParamDecl("FS_GCS_ENABLE", 1.0, 0.0, 1.0, "", "return home when the ground station is lost"),
    ParamDecl("FS_GCS_TIMEOUT", 5.0, 1.0, 300.0, "s", "ground-station silence that counts as lost"),
    ParamDecl("FS_GCS_RESUME", 1.0, 0.0, 1.0, "", "resume the mission when the link returns"),
    ParamDecl("FENCE_ENABLE", 1.0, 0.0, 1.0, "", "return home when the fence is breached"),
)


@dataclass(frozen=True)
class Action:
    """A failsafe's decision: a mode to switch to (or None) and what to tell the operator."""

    mode: FlightMode | None
    text: str
    severity: int = d.MAV_SEVERITY_CRITICAL


@dataclass
class Situation:
    """What the failsafes look at, once per step."""

    now_us: int
    mode: FlightMode
    flying: bool  # armed and in the air
    gcs_silence_s: float  # since the last ground-station heartbeat; NaN: none heard yet
    nav_flags: int
    fence_breach: str | None


class Failsafes:
    """Remembers which failsafes are active so each is announced once."""

    def __init__(self, params: dict[str, float]) -> None:
        self.params = params
        self.gcs_lost = self.gps_lost = self.fence_breached = False
        self.mode_before_gcs: FlightMode | None = None

    def step(self, s: Situation) -> list[Action]:
        """The actions this situation calls for (usually none)."""
        return [*self._gcs(s), *self._gps(s), *self._fence(s)]

    def _gcs(self, s: Situation) -> list[Action]:
        p = self.params
        silent = s.gcs_silence_s > p["FS_GCS_TIMEOUT"]  # NaN (never heard) is not silence
        if not self.gcs_lost and silent and s.flying and p["FS_GCS_ENABLE"] >= 0.5:
            self.gcs_lost, self.mode_before_gcs = True, s.mode
            return [Action(FlightMode.RTL, "Failsafe: ground station lost, returning home")]
        if self.gcs_lost and not silent:
            self.gcs_lost = False
            resume = p["FS_GCS_RESUME"] >= 0.5 and self.mode_before_gcs == FlightMode.MISSION
            if resume and s.mode == FlightMode.RTL and s.flying:
                return [Action(FlightMode.MISSION, "Ground station back: resuming the mission")]
            return [Action(None, "Ground station back", d.MAV_SEVERITY_NOTICE)]
        return []

    def _gps(self, s: Situation) -> list[Action]:
        dead_reckoning = bool(s.nav_flags & NavFlags.DEAD_RECKONING)
        if not self.gps_lost and dead_reckoning and s.flying:
            self.gps_lost = True
            return [Action(None, "Failsafe: GPS lost, holding heading and height")]
        if self.gps_lost and not dead_reckoning:
            self.gps_lost = False
            if s.flying:
                notice = d.MAV_SEVERITY_NOTICE
                return [Action(FlightMode.LOITER, "GPS back: loitering here", notice)]
        return []

    def _fence(self, s: Situation) -> list[Action]:
        enabled = self.params["FENCE_ENABLE"] >= 0.5
        if not self.fence_breached and s.fence_breach and s.flying and enabled:
            self.fence_breached = True
            return [Action(FlightMode.RTL, f"Fence breached ({s.fence_breach}): returning home")]
        if self.fence_breached and s.fence_breach is None:
            self.fence_breached = False
            return [Action(None, "Back inside the fence", d.MAV_SEVERITY_NOTICE)]
        return []
