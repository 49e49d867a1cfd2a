"""The pilot on the sticks: the mode switch, and what to do when the pilot's radio goes.

Pure: the pilot's newest inputs (RC receiver, MAVLink joystick), the navigation's sensor
time and the mode in; mode changes and operator messages out. As ArduPlane does it:
- the mode switch (``FLTMODE_CH``, read by ``sensors.rc_input``) selects ``FLTMODE1..6``
  (ArduPlane mode numbers) when it moves, and wins over the ground station, which may
  change the mode again until the switch moves next;
- RC lost (``THR_FAILSAFE``): no usable receiver frame (none at all, or the receiver's
  failsafe flag, or throttle below ``THR_FS_VALUE``) for ``FS_LONG_TIMEOUT`` seconds of
  the navigation's sensor time → Return from the modes the pilot flies (Manual,
  Stabilized; ``FS_LONG_ACTN`` 1: from every mode), and the mission goes on in Auto;
- the joystick (MANUAL_CONTROL) lost for ``RC_OVERRIDE_TIME`` while it flies the
  aircraft in Manual or Stabilized → Return.
Only a receiver or joystick that has been heard can be lost; each loss is said once, with
its cause: the receiver's failsafe flag, a failsafe throttle, silence, or the receiver's
plug-in process down (dead, or restarted since its last usable frame: an operator reading
"RC lost" must not go looking for a radio fault when a process is the cause).
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.control.failsafe import Action
from companion.control.modes import PILOT_MODES, arduplane_choices, from_arduplane
from companion.messages import FlightMode, PilotFlags, PilotInput, PluginState, SystemHealth
from companion.params import ParamDecl
from mavlink_dialect import companion as d

# A three-position switch (1000, 1500, 2000 µs) gives positions 0, 3 and 5:
# Manual, Stabilized (FBWA), Auto.
_DEFAULT_FLTMODES = (0, 0, 5, 5, 10, 10)
PILOT_PARAMS = (
    *(
        ParamDecl(
            f"FLTMODE{i + 1}",
            float(m),
            0.0,
            24.0,
            "",
            f"mode switch position {i + 1}",
            values=arduplane_choices(),
        )
        for i, m in enumerate(_DEFAULT_FLTMODES)
    ),
    ParamDecl.switch("THR_FAILSAFE", 1.0, "act when the RC receiver is lost"),
    ParamDecl("FS_LONG_TIMEOUT", 5.0, 1.0, 300.0, "s", "RC silence that counts as lost"),
    ParamDecl.switch(
        "FS_LONG_ACTN",
        0.0,
        "RC lost: 0 Return unless in Auto, 1 Return",
        "Return unless in Mission",
        "Return",
    ),
    ParamDecl("RC_OVERRIDE_TIME", 3.0, 0.5, 60.0, "s", "joystick silence that counts as lost"),
)


RC_PLUGIN = b"sensors.rc_input"  # whose process the RC failsafe names when it is down


@dataclass(frozen=True)
class ReceiverProcess:
    """The RC receiver's plug-in as the health table shows it."""

    running: bool
    restarts: int


def receiver_process(health: SystemHealth | None) -> ReceiverProcess | None:
    """The RC receiver plug-in's process in the health table (None: none listed)."""
    row = health.row_of_kind(RC_PLUGIN) if health is not None else None
    if row is None:
        return None
    return ReceiverProcess(row.state == PluginState.RUNNING, int(row.restarts))


class PilotWatch:
    """Remembers what it has announced."""

    def __init__(self, params: dict[str, float]) -> None:
        self.params = params
        self.last_usable_rc_us: int | None = None
        self.restarts_at_usable: int | None = None  # the receiver process's, at that frame
        self.rc_lost = False
        self.joystick_lost = False

    def switch_mode(self, position: int) -> FlightMode | None:
        """The mode a switch position selects (None: no such position or mode)."""
        if not 0 <= position <= 5:
            return None
        return from_arduplane(round(self.params[f"FLTMODE{position + 1}"]))

    def step(
        self,
        now_us: int,
        mode: FlightMode,
        flying: bool,
        rc: PilotInput | None,
        joystick: PilotInput | None,
        receiver: ReceiverProcess | None = None,
    ) -> list[Action]:
        """The actions the pilot's inputs call for at sensor time ``now_us`` (``receiver``:
        the receiver plug-in's process, when the health table lists one)."""
        return [
            *self._rc(now_us, mode, flying, rc, receiver),
            *self._joystick(now_us, mode, flying, rc, joystick),
        ]

    def rc_fresh(self, now_us: int, rc: PilotInput | None) -> bool:
        """Whether the receiver is flying the aircraft now."""
        return (
            rc is not None
            and rc.usable()
            and now_us - rc.t_us < self.params["FS_LONG_TIMEOUT"] * 1e6
        )

    def _rc(
        self,
        now_us: int,
        mode: FlightMode,
        flying: bool,
        rc: PilotInput | None,
        receiver: ReceiverProcess | None,
    ) -> list[Action]:
        p = self.params
        if rc is None:
            return []
        if rc.usable():
            if self.last_usable_rc_us is None or rc.t_us > self.last_usable_rc_us:
                self.restarts_at_usable = receiver.restarts if receiver is not None else None
            self.last_usable_rc_us = max(self.last_usable_rc_us or rc.t_us, rc.t_us)
        since = self.last_usable_rc_us if self.last_usable_rc_us is not None else rc.t_us
        silent = now_us - since >= p["FS_LONG_TIMEOUT"] * 1e6
        if silent and not self.rc_lost and flying and p["THR_FAILSAFE"] >= 0.5:
            self.rc_lost = True
            cause = self._lost_cause(now_us - since, rc, receiver)
            if mode in PILOT_MODES or (p["FS_LONG_ACTN"] >= 0.5 and mode != FlightMode.RTL):
                return [Action(FlightMode.RTL, f"Failsafe: RC lost, returning home ({cause})")]
            return [Action(None, f"Failsafe: RC lost, carrying on ({cause})")]
        if self.rc_lost and not silent:
            self.rc_lost = False
            return [Action(None, "RC back", d.MAV_SEVERITY_NOTICE)]
        return []

    def _lost_cause(self, silent_us: int, rc: PilotInput, receiver: ReceiverProcess | None) -> str:
        """Why no usable frame came, in a few words for the operator."""
        if receiver is not None:
            before = self.restarts_at_usable
            if not receiver.running or (before is not None and receiver.restarts > before):
                return "RC input process down"
        if rc.flags & PilotFlags.FAILSAFE:
            return "receiver failsafe"
        if rc.flags & PilotFlags.THROTTLE_LOW:
            return "failsafe throttle"
        return f"no receiver frame for {silent_us / 1e6:.0f} s"

    def _joystick(
        self,
        now_us: int,
        mode: FlightMode,
        flying: bool,
        rc: PilotInput | None,
        joystick: PilotInput | None,
    ) -> list[Action]:
        if joystick is None:
            return []
        silent = now_us - joystick.t_us >= self.params["RC_OVERRIDE_TIME"] * 1e6
        flies = mode in PILOT_MODES and not self.rc_fresh(now_us, rc)
        if silent and flies and flying and not self.joystick_lost:
            self.joystick_lost = True
            return [Action(FlightMode.RTL, "Failsafe: joystick lost, returning home")]
        if self.joystick_lost and not silent:
            self.joystick_lost = False
            return [Action(None, "Joystick back", d.MAV_SEVERITY_NOTICE)]
        return []
