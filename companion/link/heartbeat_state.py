"""What the heartbeat says of the vehicle: the commander's mode, the execution control's
arming, and nothing at all before the link has read them.

A link started beside a commander (at boot, or restarted alone in flight) sends no
heartbeat until the commander's status is read, at most COMMANDER_WAIT_S: a ground station
bears a second without heartbeats, but shows the mode a heartbeat names and acts on it
(MAVSDK and QGroundControl saw the commander's initial mode, Hold, in a restarted link's
first heartbeats). A commander silent longer than that gets heartbeats with no known mode.
"""

from __future__ import annotations

from companion.control.modes import INITIAL_MODE
from companion.link.codec import dialect as d
from companion.link.identity import VehicleState
from companion.link.mode_messages import heartbeat_mode
from companion.messages import FlightMode, SystemHealth, VehicleStatus

COMMANDER_WAIT_S = 5.0  # its status comes at 3 Hz armed, 1 Hz on the ground


class HeartbeatFollower:
    """Keeps a VehicleState as the bus says, from the commander's status and the health."""

    def __init__(
        self, state: VehicleState, commander: bool, now_s: float, px4: bool = True
    ) -> None:
        self.state = state
        self.commander = commander
        self.px4 = px4  # PX4's custom_mode packing, else ArduPlane's numbers (generic)
        self.started_s = now_s
        # Without a commander, the mode shown is the one a commander would start in.
        self.assumed: FlightMode | None = None if commander else INITIAL_MODE
        state.known = not commander
        state.custom_mode, state.mode_flags = heartbeat_mode(None, self.assumed, px4)

    def update(
        self, status: VehicleStatus | None, health: SystemHealth | None, now_s: float
    ) -> bool:
        """Take the newest status and health table; True when the mode shown changed to
        one the commander said (CURRENT_MODE is then sent at once)."""
        state = self.state
        state.known = (
            status is not None
            or not self.commander
            or now_s - self.started_s >= COMMANDER_WAIT_S  # then: no known mode, said so
        )
        custom, flags = heartbeat_mode(status, self.assumed, self.px4)
        changed = custom != state.custom_mode and status is not None
        state.custom_mode, state.mode_flags = custom, flags
        # Armed as the execution control says; until its table is read (once a second), as
        # the commander says, so a restarted link's first heartbeat is not "disarmed".
        armed = health.flight_running if health is not None else None
        if armed is None and status is not None:
            armed = status.armed
        if armed is not None:
            state.armed = bool(armed)
            state.system_status = d.MAV_STATE_ACTIVE if armed else d.MAV_STATE_STANDBY
        return changed
