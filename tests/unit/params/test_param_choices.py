"""Parameters that only mean something as a whole number or one of a few choices (a channel,
a mode switch position's mode, a failsafe that is on or off) refuse anything between, and
say so to a ground station: QGroundControl shows them whole, or as a list to pick from."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from companion.control.failsafe import FAILSAFE_PARAMS
from companion.control.modes import BY_MODE
from companion.control.pilot_watch import PILOT_PARAMS, PilotWatch
from companion.params import ParamError, ParamStore
from companion.params.metadata import parameter_entry
from companion.sensors.rc_channels import RC_PARAMS

DECLS = (*RC_PARAMS, *PILOT_PARAMS, *FAILSAFE_PARAMS)


def test_a_channel_number_with_a_fraction_is_refused_and_the_old_one_kept(tmp_path: Path):
    store = ParamStore(DECLS, tmp_path / "params.json")
    with pytest.raises(ParamError, match=r"FLTMODE_CH: 2\.5 is not a whole number"):
        store.set("FLTMODE_CH", 2.5)
    assert store.get("FLTMODE_CH") == 8.0
    assert store.set("FLTMODE_CH", 5.0) == 5.0
    with pytest.raises(ParamError, match=r"RCMAP_ROLL: 1\.2 is not a whole number"):
        store.set("RCMAP_ROLL", 1.2)


def test_a_half_enabled_failsafe_is_refused(tmp_path: Path):
    store = ParamStore(DECLS, tmp_path / "params.json")
    for name in ("FS_GCS_ENABLE", "FENCE_ENABLE", "THR_FAILSAFE", "RC3_REVERSED"):
        with pytest.raises(ParamError, match=rf"{name}: 0\.5 is not one of 0, 1"):
            store.set(name, 0.5)
    assert store.set("FENCE_ENABLE", 0.0) == 0.0


def test_a_switch_position_takes_only_a_mode_the_vehicle_flies(tmp_path: Path):
    """ArduPlane's TRAINING (3) has no counterpart here: before, it was stored and the switch
    position then did nothing in flight."""
    store = ParamStore(DECLS, tmp_path / "params.json")
    with pytest.raises(ParamError, match="FLTMODE2: 3 is not one of 0, 1, 2, 4, 5"):
        store.set("FLTMODE2", 3.0)
    store.set("FLTMODE2", 12.0)
    mode = PilotWatch({n: store.get(n) for n in store.names}).switch_mode(1)
    assert mode is not None and BY_MODE[mode].name == "Hold"


def test_each_offered_mode_is_the_mode_the_switch_then_selects():
    """The list QGroundControl shows for FLTMODE1..6 names, for each number, the mode the
    vehicle flies when the switch is there."""
    choices = next(d for d in PILOT_PARAMS if d.name == "FLTMODE1").values
    assert len(choices) >= 10
    for number, label in choices:
        watch = PilotWatch({f"FLTMODE{i}": 0.0 for i in range(2, 7)} | {"FLTMODE1": number})
        mode = watch.switch_mode(0)
        assert mode is not None, label
        assert BY_MODE[mode].name in label, (number, label)


def test_the_ground_station_is_told_whole_numbers_and_choices():
    by_name = {d.name: d for d in DECLS}
    channel = parameter_entry(by_name["FLTMODE_CH"])
    assert channel["decimalPlaces"] == 0 and channel["increment"] == 1
    assert (channel["min"], channel["max"]) == (0.0, 18.0)
    fence = parameter_entry(by_name["FENCE_ENABLE"])
    assert fence["values"] == [
        {"value": 0.0, "description": "Disabled"},
        {"value": 1.0, "description": "Enabled"},
    ]
    trim = parameter_entry(by_name["RC1_TRIM"])  # a pulse width may be any value
    assert "decimalPlaces" not in trim and "values" not in trim
    json.dumps([parameter_entry(d) for d in DECLS])  # what the metadata file holds


def test_a_stored_fraction_from_an_older_version_is_dropped_with_a_warning(tmp_path: Path, caplog):
    path = tmp_path / "params.json"
    path.write_text(json.dumps({"format": 2, "set": {"FLTMODE_CH": 6.5, "FLTMODE3": 12.0}}))
    store = ParamStore(DECLS, path)
    assert store.get("FLTMODE_CH") == 8.0 and store.get("FLTMODE3") == 12.0
    assert "FLTMODE_CH: 6.5 is not a whole number" in caplog.text
