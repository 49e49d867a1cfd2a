"""Flight modes as the ground tools name and number them.

One table says, for each ``FlightMode``: its name (AVAILABLE_MODES), its custom_mode in
PX4's packing (main mode in bits 16-23, sub mode in bits 24-31), ArduPlane's mode number
(what pymavlink and MAVProxy send for a fixed-wing that is not PX4), and MAVLink's
standard mode. The vehicle reports itself as PX4 because QGroundControl's PX4 plug-in is
the one that offers every guided action for a fixed wing (Takeoff, Start/Continue Mission,
Pause, Return, Go to, Change altitude, Orbit; src/FirmwarePlugin/PX4/PX4FirmwarePlugin.cc,
isCapable); its ArduPilot plug-in offers no take-off for a plane and its generic one no
guided action at all. Every mode has a custom_mode of its own: the PX4 ones QGroundControl
(both 4.4 and 5), MAVSDK and MAVProxy already name (our Loiter is PX4's "Hold", MAVProxy's
LOITER), and Guided, which PX4 has no built-in mode for, is PX4's first *external* mode
(AUTO, sub mode 11): the slot PX4 gives a mode that a companion computer adds, named by
AVAILABLE_MODES ("Guided" in QGroundControl 4.4.5 and 5).

The modes a pilot flies from the sticks are PX4's fixed-wing ones, because QGroundControl
4.4 offers every one of them from its own fixed table whatever the vehicle says:
Manual, Stabilized, Altitude, Position, Acro and Rattitude (PILOT_MODES).

Names are the ones QGroundControl's PX4 plug-in asks for by name from its buttons in 4.4
(src/FirmwarePlugin/PX4/PX4FirmwarePlugin.cc: Pause and Go to ask for "Hold", Return for
"Return", Start Mission for "Mission", Land for "Land", Takeoff for "Takeoff", Take
control for "Manual"). QGroundControl 4.4.5 reads AVAILABLE_MODES and, once it has them,
looks every name up in that list alone (src/Vehicle/StandardModes.cc, setFlightMode),
renaming a mode that carries a standard mode after the standard mode (SAFE_RECOVERY
"Safe Recovery", CRUISE "Cruise", ALTITUDE_HOLD "Altitude", MISSION "Mission", LAND
"Land", TAKEOFF "Takeoff"); QGroundControl 5 looks its buttons' modes up by PX4's
custom_mode instead, so the numbers must be PX4's. Hence our Loiter is named "Hold" (the
ArduPlane and MAVProxy name, LOITER, stays by number), and Return carries no standard
mode: with SAFE_RECOVERY, 4.4.5's Return button asked for a "Return" it could not find.
DO_SET_STANDARD_MODE SAFE_RECOVERY is still flown as Return.

Standard modes otherwise as PX4 reports its fixed-wing modes (Mission, Take-off, Land,
Altitude = ALTITUDE_HOLD, Position = CRUISE: the track held against the wind; QGroundControl
4.4.5 shows it as "Cruise"); our Hold is automatic, not MAVLink's pilot-driven ORBIT
(which QGroundControl would also rename "Orbit").

Reporting MAV_AUTOPILOT_GENERIC (the link's ``autopilot = "generic"``, for MAVProxy), the
vehicle numbers its modes as ArduPlane does, both ways: pymavlink names a generic fixed
wing's custom_mode from ArduPlane's table (mavutil.mode_string_v10, mode_mapping), so the
HEARTBEAT, CURRENT_MODE and AVAILABLE_MODES carry ``ModeInfo.generic`` (MAVProxy's prompt
then reads LOITER>, AUTO>, RTL>) and a main mode alone is ArduPlane's. Each ArduPlane mode
is the vehicle mode that flies as it does (``_ARDUPLANE``): CIRCLE (a circle where it is)
is Loiter, STABILIZE and FBWA (wings levelled when the sticks are released) Stabilized,
FBWB Altitude, CRUISE (heading and height held) Position, AUTOLAND Land; TRAINING,
AUTOTUNE, AVOID_ADSB, THERMAL, INITIALISING and the quadplane modes have no counterpart and
are refused. Rattitude, which ArduPlane lacks, is reported as GENERIC_RATTITUDE, a number
outside ArduPlane's table (MAVProxy shows "Mode(100)" rather than another mode's name).

``decode_set_mode`` reads DO_SET_MODE / SET_MODE in either encoding:
1. a full 32-bit PX4 custom_mode (≥ 65536) → PX4;
2. a sub mode (param3) → PX4 main/sub (MAVSDK, pymavlink for PX4);
3. reporting PX4, a main mode alone → PX4 (ArduPlane's number if PX4 has no such mode,
   except PX4's Offboard, 6, which is refused rather than read as ArduPlane's FBWB);
4. reporting generic, a main mode alone → ArduPlane's number (MAVProxy's ``mode AUTO``:
   10; ``mode CIRCLE``: 1, not PX4's MANUAL);
5. without the custom-mode flag, base_mode's AUTO/GUIDED/STABILIZE/MANUAL bits.
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.messages import FlightMode
from mavlink_dialect import companion as d

PX4_MAIN_MANUAL, PX4_MAIN_ALTCTL, PX4_MAIN_POSCTL, PX4_MAIN_AUTO = 1, 2, 3, 4
PX4_MAIN_ACRO, PX4_MAIN_STABILIZED, PX4_MAIN_RATTITUDE = 5, 7, 8
PX4_SUB_TAKEOFF, PX4_SUB_LOITER, PX4_SUB_MISSION, PX4_SUB_RTL, PX4_SUB_LAND = 2, 3, 4, 5, 6
PX4_SUB_EXTERNAL1 = 11  # PX4's first mode added from outside (a companion computer)
# PX4's Offboard (setpoints streamed by a script: MAVSDK's offboard examples), which this
# aircraft does not fly. Its number is ArduPlane's FBWB too, and MAVSDK's Offboard.start()
# was taken for Altitude, reported accepted, and the script went on streaming setpoints
# nobody followed; reporting PX4, it is refused by name.
PX4_MAIN_OFFBOARD = 6


# The mode the commander starts in (PX4's "Hold": a fixed wing without a pilot circles);
# the link names it from the first heartbeat, before the commander has spoken.
INITIAL_MODE = FlightMode.LOITER


def px4_custom_mode(main: int, sub: int = 0) -> int:
    """PX4's packing of main and sub mode into custom_mode."""
    return (main << 16) | (sub << 24)


@dataclass(frozen=True)
class ModeInfo:
    """One mode in every encoding."""

    mode: FlightMode
    name: str
    px4: int  # custom_mode
    arduplane: int
    standard: int  # MAV_STANDARD_MODE
    base_flags: int  # MAV_MODE_FLAG bits besides CUSTOM_MODE_ENABLED and SAFETY_ARMED
    user_selectable: bool = True

    @property
    def generic(self) -> int:
        """Its custom_mode reporting MAV_AUTOPILOT_GENERIC: ArduPlane's number."""
        return GENERIC_RATTITUDE if self.arduplane == NO_ARDUPLANE else self.arduplane

    def custom_mode(self, px4: bool) -> int:
        """Its custom_mode reporting PX4 (``px4``) or generic."""
        return self.px4 if px4 else self.generic

    @property
    def pilot(self) -> bool:
        """Flown from the pilot's sticks (the receiver's, else the joystick's)."""
        return bool(self.base_flags & d.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED)


_AUTO = d.MAV_MODE_FLAG_AUTO_ENABLED | d.MAV_MODE_FLAG_GUIDED_ENABLED
_STAB = d.MAV_MODE_FLAG_STABILIZE_ENABLED
_NONE = d.MAV_STANDARD_MODE_NON_STANDARD
_PILOT = d.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
NO_ARDUPLANE = -1  # ArduPlane has no such mode: a switch position cannot select it
GENERIC_RATTITUDE = 100  # Rattitude's number reporting generic: not one of ArduPlane's
MODES: tuple[ModeInfo, ...] = (
    ModeInfo(FlightMode.MANUAL, "Manual", px4_custom_mode(PX4_MAIN_MANUAL), 0,
             _NONE, _PILOT),
    ModeInfo(FlightMode.STABILIZED, "Stabilized", px4_custom_mode(PX4_MAIN_STABILIZED), 5,
             _NONE, _STAB | _PILOT),
    # ArduPlane's FBWB and CRUISE are these two; its ACRO is Acro; it has no Rattitude.
    ModeInfo(FlightMode.ALTITUDE, "Altitude", px4_custom_mode(PX4_MAIN_ALTCTL), 6,
             d.MAV_STANDARD_MODE_ALTITUDE_HOLD, _STAB | _PILOT),
    ModeInfo(FlightMode.POSITION, "Position", px4_custom_mode(PX4_MAIN_POSCTL), 7,
             d.MAV_STANDARD_MODE_CRUISE, _STAB | d.MAV_MODE_FLAG_GUIDED_ENABLED | _PILOT),
    ModeInfo(FlightMode.ACRO, "Acro", px4_custom_mode(PX4_MAIN_ACRO), 4, _NONE, _PILOT),
    ModeInfo(FlightMode.RATTITUDE, "Rattitude", px4_custom_mode(PX4_MAIN_RATTITUDE),
             NO_ARDUPLANE, _NONE, _STAB | _PILOT),
    ModeInfo(FlightMode.MISSION, "Mission", px4_custom_mode(PX4_MAIN_AUTO, PX4_SUB_MISSION), 10,
             d.MAV_STANDARD_MODE_MISSION, _STAB | _AUTO),
    ModeInfo(FlightMode.LOITER, "Hold", px4_custom_mode(PX4_MAIN_AUTO, PX4_SUB_LOITER), 12,
             _NONE, _STAB | _AUTO),
    # Not SAFE_RECOVERY: QGroundControl 4.4 would rename it "Safe Recovery" (see above).
    ModeInfo(FlightMode.RTL, "Return", px4_custom_mode(PX4_MAIN_AUTO, PX4_SUB_RTL), 11,
             _NONE, _STAB | _AUTO),
    ModeInfo(FlightMode.GUIDED, "Guided", px4_custom_mode(PX4_MAIN_AUTO, PX4_SUB_EXTERNAL1), 15,
             _NONE, _STAB | d.MAV_MODE_FLAG_GUIDED_ENABLED),
    ModeInfo(FlightMode.TAKEOFF, "Takeoff", px4_custom_mode(PX4_MAIN_AUTO, PX4_SUB_TAKEOFF), 13,
             d.MAV_STANDARD_MODE_TAKEOFF, _STAB | _AUTO),
    # Listed so every tool can name it, not offered in a mode list: it lands only a stored
    # mission that has a DO_LAND_START (from there, at once), and is refused otherwise.
    ModeInfo(FlightMode.LAND, "Land", px4_custom_mode(PX4_MAIN_AUTO, PX4_SUB_LAND), 26,
             d.MAV_STANDARD_MODE_LAND, _STAB | _AUTO, user_selectable=False),
)  # fmt: skip
BY_MODE = {m.mode: m for m in MODES}
PILOT_MODES = frozenset(m.mode for m in MODES if m.pilot)
_ARDUPLANE = {m.arduplane: m.mode for m in MODES if m.arduplane != NO_ARDUPLANE} | {
    1: FlightMode.LOITER,  # CIRCLE: circles where it is, as our Loiter
    2: FlightMode.STABILIZED,  # STABILIZE: levels the wings when the sticks are released
}
_GENERIC = _ARDUPLANE | {GENERIC_RATTITUDE: FlightMode.RATTITUDE}
_PX4 = {m.px4: m.mode for m in MODES}
_STANDARD = {m.standard: m.mode for m in MODES if m.standard != d.MAV_STANDARD_MODE_NON_STANDARD}
_STANDARD[d.MAV_STANDARD_MODE_ORBIT] = FlightMode.LOITER  # the nearest we fly
_STANDARD[d.MAV_STANDARD_MODE_SAFE_RECOVERY] = FlightMode.RTL  # asked for, still flown


def from_px4(main: int, sub: int) -> FlightMode | None:
    """A PX4 main/sub mode pair (sub 0 for the non-auto modes)."""
    if main != PX4_MAIN_AUTO:
        sub = 0
    return _PX4.get(px4_custom_mode(main, sub))


def decode_set_mode(
    base_mode: int, custom: int, sub: int = 0, reporting_px4: bool = False
) -> FlightMode | None:
    """The mode a DO_SET_MODE (param1..3) or SET_MODE asks for, or None if unknown."""
    if not base_mode & d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
        return _from_base_flags(base_mode)
    if custom >= 1 << 16:
        return from_px4((custom >> 16) & 0xFF, (custom >> 24) & 0xFF)
    if sub or reporting_px4:
        mode = from_px4(custom, sub)
        if mode is not None or sub or (reporting_px4 and custom == PX4_MAIN_OFFBOARD):
            return mode
    return _ARDUPLANE.get(custom) if reporting_px4 else _GENERIC.get(custom)


def from_generic(custom_mode: int) -> FlightMode | None:
    """The mode a generic-reporting heartbeat's custom_mode names (ArduPlane's number)."""
    return _GENERIC.get(custom_mode)


def from_standard(standard_mode: int) -> FlightMode | None:
    """DO_SET_STANDARD_MODE's mode."""
    return _STANDARD.get(standard_mode)


def _from_base_flags(base_mode: int) -> FlightMode | None:
    if base_mode & d.MAV_MODE_FLAG_AUTO_ENABLED:
        return FlightMode.MISSION
    if base_mode & d.MAV_MODE_FLAG_GUIDED_ENABLED:
        return FlightMode.GUIDED
    if base_mode & d.MAV_MODE_FLAG_STABILIZE_ENABLED:
        return FlightMode.STABILIZED
    if base_mode & d.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED:
        return FlightMode.MANUAL
    return None


def from_arduplane(number: int) -> FlightMode | None:
    """An ArduPlane mode number (FLTMODE1..6 hold these), whatever the other encodings say."""
    return _ARDUPLANE.get(number)


# ArduPlane's own names for the numbers ``_ARDUPLANE`` reads, as its users know them.
_ARDUPLANE_NAMES = {0: "MANUAL", 1: "CIRCLE", 2: "STABILIZE", 4: "ACRO", 5: "FBWA", 6: "FBWB",
                    7: "CRUISE", 10: "AUTO", 11: "RTL", 12: "LOITER", 13: "TAKEOFF",
                    15: "GUIDED", 26: "AUTOLAND"}  # fmt: skip


def arduplane_choices() -> tuple[tuple[float, str], ...]:
    """Every ArduPlane mode number a switch position may hold (not Land, which no mode
    list offers), named as ArduPlane names it and, where another, as this vehicle does
    (``FBWA (Stabilized)``)."""
    choices = []
    for number, mode in sorted(_ARDUPLANE.items()):
        if not BY_MODE[mode].user_selectable:
            continue
        ours = BY_MODE[mode].name
        theirs = _ARDUPLANE_NAMES.get(number, str(number))
        same = theirs.lower() == ours.lower()
        choices.append((float(number), ours if same else f"{theirs} ({ours})"))
    return tuple(choices)
