"""What the flight controller reports, as MAVLink: NAV_CONTROLLER_OUTPUT, MISSION_CURRENT
while a mission runs, MISSION_ITEM_REACHED, and the landed state."""

from __future__ import annotations

import math
from typing import Any

from companion.link.codec import dialect as d
from companion.messages import ControlStatus, LandPhase, MissionState, TakeoffPhase

LANDING_PHASES = (LandPhase.APPROACH, LandPhase.FLARE, LandPhase.ROLLOUT)
# Not ABORTED: a take-off given up is on the ground.
TAKEOFF_PHASES = (TakeoffPhase.GROUND_ROLL, TakeoffPhase.ROTATE, TakeoffPhase.CLIMB_OUT)


def _deg(rad: float) -> float:
    return math.degrees(rad) if math.isfinite(rad) else 0.0


def _finite(x: float) -> float:
    return x if math.isfinite(x) else 0.0


def mission_items_reached(mav: Any, c: ControlStatus, told: int) -> list[Any]:
    """MISSION_ITEM_REACHED for each item reached since ``told`` items were (-1: none told
    yet, the link just started: the last one only, as before it began). A controller
    restarted counts from 0 again: all it has reached."""
    count, kept = c.reached_count, ControlStatus.REACHED_KEPT
    if c.last_reached < 0 or count == told:
        return []
    first = count - 1 if told < 0 else (told if told < count else 0)
    seqs = [c.recent_reached[n % kept] for n in range(max(first, count - kept), count)]
    return [mav.mission_item_reached_encode(seq) for seq in seqs if seq >= 0]


def nav_controller_output(mav: Any, c: ControlStatus | None) -> Any:
    """Guidance demands and errors (bearings in whole degrees, as the message has them)."""
    if c is None:
        return None
    return mav.nav_controller_output_encode(
        _deg(c.nav_roll_rad),
        _deg(c.nav_pitch_rad),
        round(_deg(c.target_bearing_rad)) % 360,
        round(_deg(c.target_bearing_rad)) % 360,
        max(0, min(65535, round(_finite(c.wp_dist_m)))),
        _finite(c.alt_error_m),
        _finite(c.aspd_error_m_s),
        _finite(c.xtrack_error_m),
    )


def mission_current(
    mav: Any,
    stored_seq: int,
    total: int,
    c: ControlStatus | None,
    completed: bool = False,
    paused: bool = False,
) -> Any:
    """MISSION_CURRENT: the executor's item and state while it runs, else the stored one
    (complete at its last item once it was flown to the end, also in the Return its
    NAV_RETURN_TO_LAUNCH entered; paused at the item it was at once it was flown and left,
    as PX4 and ArduPilot keep it)."""
    if total == 0:
        return mav.mission_current_encode(stored_seq, 0, d.MISSION_STATE_NO_MISSION)
    if c is None or c.mission_state == MissionState.NOT_STARTED:
        if completed:
            return mav.mission_current_encode(total - 1, total, d.MISSION_STATE_COMPLETE)
        state = d.MISSION_STATE_PAUSED if paused else d.MISSION_STATE_NOT_STARTED
        return mav.mission_current_encode(stored_seq, total, state)
    seq = max(0, min(int(c.mission_seq), total - 1))
    return mav.mission_current_encode(seq, total, int(c.mission_state))


def landed_state(c: ControlStatus | None) -> int | None:
    """MAV_LANDED_STATE from the controller, or None when it is not running.

    TAKEOFF from the start of the take-off roll until the take-off height; LANDING on the
    approach, in the flare and on the rollout until the aircraft has stopped (a go-around
    is IN_AIR). QGroundControl offers its "Land Abort" for a fixed wing only in LANDING
    (Vehicle::_handleExtendedSysState sets ``landing``, GuidedActionsController.qml
    ``_fixedWingOnApproach``), and counts TAKEOFF and LANDING as flying.
    """
    if c is None:
        return None
    if c.takeoff_phase in TAKEOFF_PHASES:
        return d.MAV_LANDED_STATE_TAKEOFF
    if c.land_phase in LANDING_PHASES:
        return d.MAV_LANDED_STATE_LANDING
    return d.MAV_LANDED_STATE_ON_GROUND if c.landed else d.MAV_LANDED_STATE_IN_AIR


def rc_channels(mav: Any, s: Any) -> Any:
    """RC_CHANNELS from a telemetry snapshot's receiver frame (none without a receiver:
    QGroundControl's radio page then stays empty)."""
    rc = s.rc
    if rc is None:
        return None
    count = min(rc.channel_count, len(rc.channels_us))
    return mav.rc_channels_encode(s.time_boot_ms, count, *list(rc.channels_us), rc.rssi)
