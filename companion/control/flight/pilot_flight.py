"""How the flight controller flies the pilot's modes: by attitude (Manual, Stabilized, Acro,
Rattitude: ``pilot.py``) or with the height and track held (Altitude, Position:
``assisted.py``, flown by the same energy controller and line guidance as a mission).

A mix-in of ``FlightController`` (companion/control/flight/controller.py), kept apart so
each file stays one subject.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from companion.control.flight.attitude_modes import Sticks, fly_pilot
from companion.control.laws.limits import clamp
from companion.messages import FlightMode, NavState

if TYPE_CHECKING:
    from companion.control.flight.controller import FlightController
    from companion.control.flight.output import ControlOutput

ASSISTED_MODES = frozenset({FlightMode.ALTITUDE, FlightMode.POSITION})


class PilotFlight:
    """The pilot's modes, for ``FlightController``."""

    def _fly_sticks(
        self: FlightController,
        mode: FlightMode,
        sticks: Sticks,
        pos: tuple[float, float],
        vel: tuple[float, float],
        nav: NavState,
        airspeed: float,
        dt: float,
        out: ControlOutput,
    ) -> ControlOutput:
        """The pilot's ``mode`` from these sticks at ``pos`` and ``vel`` (local N, E)."""
        key = (int(mode), -1)  # a pilot's mode is entered once, whatever the commands
        if key != self._mode_key:
            self.assisted.reset()
            self.acro.reset()
        self._mode_key = key
        if mode in ASSISTED_MODES and self.landed:
            # On the wheels there is no height to hold, and the energy controller would open
            # the throttle to reach flying speed: the pilot's throttle stick has it, as in
            # Stabilized, until the aircraft has left the ground.
            mode = FlightMode.STABILIZED
        elif mode in ASSISTED_MODES:
            demand = self.assisted.step(mode, sticks, pos, nav, self.config)
            self.tecs.gains = self.config.tecs
            out = self._fly(
                demand.setpoint, pos, vel, nav, airspeed, dt, out,
                climb_ff=demand.climb_ff, roll_dem=demand.roll,
            )  # fmt: skip
            out.rudder = clamp(out.rudder + sticks.yaw, -1.0, 1.0)
            return out
        cfg = self.config
        demand = fly_pilot(mode, sticks, nav, airspeed, dt, self.attitude, cfg, self.acro)
        out.aileron, out.elevator, out.rudder = demand.aileron, demand.elevator, demand.rudder
        out.throttle = demand.throttle
        out.nav_roll, out.nav_pitch = demand.roll, demand.pitch
        self.tecs.reset(nav.pitch_rad)  # Auto takes over from the attitude the pilot left
        return out
