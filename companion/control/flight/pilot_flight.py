"""How the flight controller flies the pilot's modes: by attitude (Manual, Stabilized, Acro,
Rattitude: ``attitude_modes.py``) or with the height and track held (Altitude, Position:
``assisted.py``, flown by the same energy controller and line guidance as a mission).

A collaborator of ``FlightController``: given the attitude controller and the energy
controller it shares, and per step the parameters and the controller's line flying.
"""

from __future__ import annotations

from collections.abc import Callable

from companion.control.flight.assisted import AssistedHold
from companion.control.flight.attitude_modes import AcroHold, Sticks, fly_pilot
from companion.control.flight.flight_params import FlightConfig
from companion.control.flight.output import ControlOutput
from companion.control.laws.attitude import AttitudeController
from companion.control.laws.limits import clamp
from companion.control.laws.tecs import Tecs
from companion.messages import FlightMode, NavState

ASSISTED_MODES = frozenset({FlightMode.ALTITUDE, FlightMode.POSITION})


class PilotFlight:
    """The pilot's modes, for ``FlightController``."""

    def __init__(self, attitude: AttitudeController, tecs: Tecs) -> None:
        self.attitude = attitude
        self.tecs = tecs
        self.acro = AcroHold()
        self.assisted = AssistedHold()

    def reset(self) -> None:
        """A pilot's mode entered: the holds start afresh."""
        self.assisted.reset()
        self.acro.reset()

    def fly(
        self,
        mode: FlightMode,
        sticks: Sticks,
        motion: tuple[tuple[float, float], tuple[float, float], NavState, float, float],
        out: ControlOutput,
        config: FlightConfig,
        landed: bool,
        fly_line: Callable[..., ControlOutput],
    ) -> ControlOutput:
        """The pilot's ``mode`` from these sticks; ``motion`` is position and velocity (local
        N, E), the navigation solution, the airspeed and the time step. ``fly_line`` flies a
        setpoint by the energy controller and the line guidance (``FlightController._fly``)."""
        pos, vel, nav, airspeed, dt = motion
        if mode in ASSISTED_MODES and landed:
            # On the wheels there is no height to hold, and the energy controller would open
            # the throttle to reach flying speed: the pilot's throttle stick has it, as in
            # Stabilized, until the aircraft has left the ground.
            mode = FlightMode.STABILIZED
        elif mode in ASSISTED_MODES:
            demand = self.assisted.step(mode, sticks, pos, nav, config)
            self.tecs.gains = config.tecs
            out = fly_line(
                demand.setpoint, pos, vel, nav, airspeed, dt, out,
                climb_ff=demand.climb_ff, roll_dem=demand.roll,
            )  # fmt: skip
            out.rudder = clamp(out.rudder + sticks.yaw, -1.0, 1.0)
            return out
        att = fly_pilot(mode, sticks, nav, airspeed, dt, self.attitude, config, self.acro)
        out.aileron, out.elevator, out.rudder = att.aileron, att.elevator, att.rudder
        out.throttle = att.throttle
        out.nav_roll, out.nav_pitch = att.roll, att.pitch
        self.tecs.reset(nav.pitch_rad)  # Auto takes over from the attitude the pilot left
        return out
