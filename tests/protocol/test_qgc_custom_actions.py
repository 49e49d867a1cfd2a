"""The QGroundControl custom actions the project ships, in the format each version reads.

QGroundControl 4.4 reads a ``CustomActions`` file (``CustomActionManager::_loadFromJson``:
``label`` and ``mavCmd`` required, ``compId`` and ``param1``..``param7`` optional numbers;
an action that fails is skipped); QGroundControl 5 reads a ``MavlinkActions`` file
(``MavlinkActionManager``: ``description`` required as well; one bad action rejects the
file). Both open it with ``openInternalQGCJsonFile``: a JSON object whose ``fileType`` is
the expected one and whose ``version`` is a number from 1 to 1. The loaders below do the
same checks, and each shipped file is also sent to a vehicle action by action as
QGroundControl sends it (``sendTo``: COMMAND_LONG, absent params 0, to ``compId`` or 1).
Neither format has a confirmation field: both versions send on the click.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from companion.messages import FlightMode
from mavlink_dialect import companion as m
from tests.protocol.test_modes import PX4, heartbeat_mode, station  # noqa: F401 - fixture
from tests.support.vehicle import REPO, wait_for

QGC44 = REPO / "qgc/companion-actions.qgc4.4.json"
QGC5 = REPO / "qgc/companion-actions.qgc5.json"
PARAMS = tuple(f"param{i}" for i in range(1, 8))


class LoadError(ValueError):
    """What QGroundControl would log instead of loading the file."""


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)  # QJsonValue::Double


def _open_internal(path: Path, file_type: str) -> dict[str, Any]:
    """``openInternalQGCJsonFile(path, file_type, 1, 1, ...)``."""
    doc = json.loads(path.read_text())
    if not isinstance(doc, dict):
        raise LoadError("Root of json file is not object")
    if not isinstance(doc.get("fileType"), str) or not _number(doc.get("version")):
        raise LoadError("fileType and version keys required")
    if doc["fileType"] != file_type:
        raise LoadError(f"Incorrect file type key expected:{file_type} actual:{doc['fileType']}")
    if not 1 <= int(doc["version"]) <= 1:
        raise LoadError(f"File version {doc['version']} not supported")
    if not isinstance(doc.get("actions"), list):
        raise LoadError("actions array required")
    return doc


def _valid(action: Any, required: tuple[str, ...]) -> bool:
    if not isinstance(action, dict) or not all(k in action for k in required):
        return False
    strings = [k for k in ("label", "description") if k in action]
    numbers = [k for k in ("mavCmd", "compId", *PARAMS) if k in action]
    return all(isinstance(action[k], str) for k in strings) and all(
        _number(action[k]) for k in numbers
    )


def _command(action: dict[str, Any]) -> tuple[str, int, int, tuple[float, ...]]:
    params = tuple(float(action.get(p, 0.0)) for p in PARAMS)
    return action["label"], int(action["mavCmd"]), int(action.get("compId", 1)), params


def load_qgc44(path: Path) -> list[tuple[str, int, int, tuple[float, ...]]]:
    """QGroundControl 4.4's loader: invalid actions are skipped (we count them as errors)."""
    doc = _open_internal(path, "CustomActions")
    actions = doc["actions"]
    if not all(_valid(a, ("label", "mavCmd")) for a in actions):
        raise LoadError("an action would be skipped")
    return [_command(a) for a in actions]


def load_qgc5(path: Path) -> list[tuple[str, int, int, tuple[float, ...]]]:
    """QGroundControl 5's loader: one invalid action rejects the whole file."""
    doc = _open_internal(path, "MavlinkActions")
    if not all(_valid(a, ("label", "description", "mavCmd")) for a in doc["actions"]):
        raise LoadError("incorrect format")
    return [_command(a) for a in doc["actions"]]


EXPECTED = {
    "Takeoff": FlightMode.TAKEOFF,  # 4.4.5 greys out its own Takeoff for a fixed wing
    "Start Mission": FlightMode.MISSION,
    "Return": FlightMode.RTL,
    "Land": FlightMode.LAND,  # neither version offers its own Land for a fixed wing
    "Loiter": FlightMode.LOITER,
    "Stabilized": FlightMode.STABILIZED,
}


# QGroundControl 5's Actions panel lists its own Start Mission above the custom actions
# whenever a plan is on the vehicle: the custom one is named apart from it there.
RENAMED_IN_5 = {"Start Mission": "Resume Mission"}


def test_each_version_loads_its_own_file_and_refuses_the_other():
    for_44, for_5 = load_qgc44(QGC44), load_qgc5(QGC5)
    # The same commands, whichever QGroundControl, under the labels each can tell apart.
    assert [(RENAMED_IN_5.get(label, label), *rest) for label, *rest in for_44] == for_5
    assert [label for label, *_ in for_44] == list(EXPECTED)
    with pytest.raises(LoadError, match="expected:CustomActions actual:MavlinkActions"):
        load_qgc44(QGC5)  # what QGroundControl 4.4.5 logged for the file shipped before
    with pytest.raises(LoadError, match="expected:MavlinkActions actual:CustomActions"):
        load_qgc5(QGC44)


def test_the_loaders_refuse_what_qgroundcontrol_refuses(tmp_path):
    good = json.loads(QGC5.read_text())
    cases = {
        "no description (QGC 5)": {**good, "actions": [{"label": "x", "mavCmd": 20}]},
        "mavCmd as text": {**good, "actions": [{**good["actions"][0], "mavCmd": "20"}]},
        "version 2": {**good, "version": 2},
        "no actions": {"version": 1, "fileType": "MavlinkActions"},
    }
    for name, doc in cases.items():
        path = tmp_path / "actions.json"
        path.write_text(json.dumps(doc))
        with pytest.raises(LoadError):
            load_qgc5(path)
            pytest.fail(name)


def test_every_shipped_action_does_what_its_label_says(station):  # noqa: F811 - fixture
    _, gcs, status = station(with_mission=True)
    for label, command, compid, params in load_qgc44(QGC44):
        gcs.command(command, *params, target=(1, compid))
        assert gcs.ack(command).result == m.MAV_RESULT_ACCEPTED, label
        mode = EXPECTED[label]
        wait_for(lambda mode=mode: status.get().mode == mode, 3.0, label)
        heartbeat_mode(gcs, PX4[mode])
