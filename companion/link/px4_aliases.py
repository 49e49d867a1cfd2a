"""PX4's names for settings the vehicle has under its own (ArduPilot-style) names.

QGroundControl's PX4 setup pages show and change these (``companion.link.px4_compat`` lists
which page reads what). Each is an alias (``companion.params.alias``): one value, the owner's,
read and written in PX4's meaning and units, so changing "RC loss action" on the Safety
page changes what the commander does. PX4 choices the vehicle cannot fly (Hold, Land,
Terminate, Disarm as a failsafe; a timed loiter before landing) are not offered: the
enumeration served to QGroundControl lists what the vehicle does, and a write of anything
else gets the old value back. Where the owner is not in the config (no commander, no
battery monitor, no controller) the name is a fixed fact at the default given here, which
is what such a vehicle does (no failsafe acts without a commander: "Disabled").
"""

from __future__ import annotations

from companion.control.modes import MODES, from_arduplane
from companion.messages import FlightMode
from companion.params import ParamDecl
from companion.params.alias import Alias
from companion.sensors.rc_channels import CALIBRATED_CHANNELS

Values = tuple[tuple[float, str], ...]
Rows = tuple[tuple[float, tuple[float, ...]], ...]


def _same(name: str, target: str, doc: str, unit: str = "", default: float = 0.0) -> ParamDecl:
    """The owner's value under PX4's name, in the same unit (range and default follow)."""
    return ParamDecl(name, default, unit=unit, doc=f"{doc} (= {target})", alias=Alias((target,)))


def _choice(
    name: str, targets: tuple[str, ...], rows: Rows, values: Values, doc: str,
    default: float = 0.0,
) -> ParamDecl:  # fmt: skip
    """An enumeration read from (and written to) the owners' switches: the first row the
    owners match is read, the first row of a value is written."""
    alias = Alias(targets, table=rows, other=default)
    owners = ", ".join(targets)
    return ParamDecl(name, default, values=values, doc=f"{doc} (= {owners})", alias=alias)


def _channels(first: int, last: int) -> Values:
    """RC channel numbers as PX4 names them (0: none)."""
    return tuple((float(n), f"Channel {n}" if n else "Unassigned") for n in range(first, last + 1))


_SWITCH = ((0.0, (0.0,)), (2.0, (1.0,)))  # PX4's Disabled and Return: the owner's 0 and 1
_OFF, _RETURN = (0.0, "Disabled"), (2.0, "Return mode")
SAFETY_ALIASES = (
    _choice("NAV_RCL_ACT", ("THR_FAILSAFE",), _SWITCH, (_OFF, _RETURN),
            "RC receiver lost while flying: Return from Manual and Stabilized (from every "
            "mode with FS_LONG_ACTN 1)"),
    _same("COM_RC_LOSS_T", "FS_LONG_TIMEOUT", "RC receiver silence that counts as lost", "s"),
    _choice("NAV_DLL_ACT", ("FS_GCS_ENABLE",), _SWITCH, (_OFF, _RETURN),
            "Ground station lost while flying: Return"),
    _same("COM_DL_LOSS_T", "FS_GCS_TIMEOUT", "Ground-station silence that counts as lost",
          "s"),
    _choice("GF_ACTION", ("FENCE_ENABLE",), ((0.0, (0.0,)), (3.0, (1.0,))),
            ((0.0, "None"), (3.0, "Return mode")), "Outside the uploaded fence while flying"),
    _same("RTL_RETURN_ALT", "RTL_ALT_M", "Return altitude above home", "m"),
    _same("RTL_DESCEND_ALT", "RTL_LOITER_ALT_M",
          "Loiter altitude above home after the return: descended to on arriving, never "
          "climbed to", "m"),
    # PX4's 0 lands after the return; with RTL_AUTOLAND 2 the aircraft goes to the landing
    # without reaching home first (PX4's RTL_TYPE), which also reads as 0.
    _choice("RTL_LAND_DELAY", ("RTL_AUTOLAND",), ((-1.0, (0.0,)), (0.0, (1.0,)), (0.0, (2.0,))),
            ((-1.0, "Loiter at home, do not land"), (0.0, "Land (at the mission's landing)")),
            "After the return: lands only at a mission's DO_LAND_START, loiters otherwise",
            default=-1.0),
    # PX4's 0 is "never", which the vehicle does not offer: the least it takes is 0.1 s.
    ParamDecl("COM_DISARM_LAND", 0.0, 0.1, unit="s", alias=Alias(("LAND_DISARMDELAY",)),
              doc="Disarm this long after the landing stopped (= LAND_DISARMDELAY)"),
)  # fmt: skip

# The low and critical levels' actions; PX4 has no "return at the low level": 1 is ours.
BATTERY_ALIASES = (
    _choice("COM_LOW_BAT_ACT", ("BATT_FS_LOW_ACT", "BATT_FS_CRT_ACT"),
            ((0.0, (0.0, 0.0)), (3.0, (0.0, 1.0)), (1.0, (1.0, 1.0)), (1.0, (1.0, 0.0))),
            ((0.0, "Warning"), (1.0, "Return at the low level"),
             (3.0, "Return at the critical level")),
            "Battery failsafe while flying"),
    ParamDecl("BAT_LOW_THR", 0.0, 0.0, 1.0, "norm", "Low when this fraction of the capacity "
              "is left (= BATT_LOW_MAH / BATT_CAPACITY; 0: voltage only)",
              alias=Alias(("BATT_LOW_MAH",), divisor="BATT_CAPACITY")),
    ParamDecl("BAT_CRIT_THR", 0.0, 0.0, 1.0, "norm", "Critical when this fraction of the "
              "capacity is left (= BATT_CRT_MAH / BATT_CAPACITY; 0: voltage only)",
              alias=Alias(("BATT_CRT_MAH",), divisor="BATT_CAPACITY")),
    _same("BAT1_CAPACITY", "BATT_CAPACITY", "Pack capacity (0: unknown)", "mAh"),
)  # fmt: skip

# COM_FLTMODEn: PX4's mode numbers (Guided is PX4's first external mode, 100).
PX4_SLOT = {FlightMode.MANUAL: 0, FlightMode.ALTITUDE: 1, FlightMode.POSITION: 2,
            FlightMode.MISSION: 3, FlightMode.LOITER: 4, FlightMode.RTL: 5,
            FlightMode.ACRO: 6, FlightMode.STABILIZED: 8, FlightMode.TAKEOFF: 10,
            FlightMode.GUIDED: 100}  # fmt: skip
UNASSIGNED = -1.0  # the switch position selects no mode


def _mode_rows() -> Rows:
    """PX4 slot → ArduPlane number (what FLTMODEn holds): each mode's own number first,
    the one written; then the other numbers ``from_arduplane`` reads as the same mode."""
    own = tuple(
        (float(PX4_SLOT[m.mode]), (float(m.arduplane),)) for m in MODES if m.mode in PX4_SLOT
    )
    more = tuple(
        (float(PX4_SLOT[mode]), (float(n),))
        for n in range(25)
        if (mode := from_arduplane(n)) in PX4_SLOT and all(row[1] != (n,) for row in own)
    )
    return (*own, *more)


def _mode_slot(position: int) -> ParamDecl:
    """COM_FLTMODEn: the mode FLTMODEn selects, by PX4's number."""
    names = {float(PX4_SLOT[m.mode]): m.name for m in MODES if m.mode in PX4_SLOT}
    values = ((UNASSIGNED, "Unassigned"), *sorted(names.items()))
    target = f"FLTMODE{position}"
    alias = Alias((target,), table=_mode_rows(), other=UNASSIGNED)
    doc = f"Mode at switch position {position} (= {target}, ArduPlane's numbers)"
    return ParamDecl(f"COM_FLTMODE{position}", UNASSIGNED, values=values, doc=doc, alias=alias)


def _reversed(n: int) -> ParamDecl:
    values = ((-1.0, "Reverse"), (1.0, "Normal"))
    alias = Alias((f"RC{n}_REVERSED",), table=((-1.0, (1.0,)), (1.0, (0.0,))), other=1.0)
    doc = f"RC channel {n} direction (= RC{n}_REVERSED: 1 is -1 here)"
    return ParamDecl(f"RC{n}_REV", 1.0, values=values, doc=doc, alias=alias)


RC_ALIASES = (
    *(
        ParamDecl(f"RC_MAP_{axis}", 0.0, values=_channels(0, CALIBRATED_CHANNELS),
                  doc=f"RC channel of the {axis.lower()} stick (= RCMAP_{axis})",
                  alias=Alias((f"RCMAP_{axis}",)))
        for axis in ("ROLL", "PITCH", "YAW", "THROTTLE")
    ),
    ParamDecl("RC_MAP_FLTMODE", 0.0, values=_channels(0, 18), alias=Alias(("FLTMODE_CH",)),
              doc="RC channel of the six-position mode switch (= FLTMODE_CH)"),
    *(_mode_slot(position) for position in range(1, 7)),
    *(_reversed(n) for n in range(1, CALIBRATED_CHANNELS + 1)),
)  # fmt: skip
PX4_ALIASES = (*SAFETY_ALIASES, *BATTERY_ALIASES, *RC_ALIASES)
