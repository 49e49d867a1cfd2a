"""Parameters store only what the user set: a value the user never touched follows the
airframe file after it is edited, through a restart, even after another parameter was set
from QGroundControl (and from a file the previous version wrote, pinning every value)."""

from __future__ import annotations

import json

import pytest

from companion.actuators.airframe import AIRFRAMES_DIR
from companion.params.live import LiveParams
from companion.plugins.control.fixed_wing import FixedWingPlugin
from tests.protocol.test_qgc_setup_pages import param_set, start
from tests.support.configs import client_vehicle, plugin

SHIPPED = (AIRFRAMES_DIR / "J3Cub.toml").read_text()


def read(gcs, name: str) -> float:
    """PARAM_REQUEST_READ by name, as QGroundControl refreshes one value."""
    gcs.mav.param_request_read_send(1, 1, name.encode(), -1)
    return gcs.recv("PARAM_VALUE", 15.0, param_id=name).param_value


@pytest.mark.parametrize("history", ["set from QGroundControl", "old file pinning every value"])
def test_an_airframe_edit_reaches_a_parameter_the_user_never_set(
    vehicle_factory, tmp_path, history
):
    airframe = tmp_path / "J3Cub.toml"
    airframe.write_text(SHIPPED)
    assert "NAVL1_PERIOD = 14.0" in SHIPPED
    state = tmp_path / "state"
    state.mkdir()
    control = plugin("control", "control.fixed_wing", group="flight")

    def config(port: int, state_dir) -> str:
        return client_vehicle(
            f"udpin://127.0.0.1:{port}", state_dir, flight=control, airframe=str(airframe)
        )

    decls = FixedWingPlugin.param_decls({}, {"airframe": str(airframe)})
    if history.startswith("old"):  # as the previous version wrote it: every value
        pinned = {d.name: d.default for d in decls} | {"WP_RADIUS": 45.0}
        (state / "params.json").write_text(json.dumps(pinned))
    vehicle, gcs = start(vehicle_factory, state, config)
    assert read(gcs, "NAVL1_PERIOD") == 14.0
    if history.startswith("set"):
        param_set(gcs, "WP_RADIUS", 45.0)  # an unrelated parameter
    gcs.close()
    vehicle.close()

    airframe.write_text(SHIPPED.replace("NAVL1_PERIOD = 14.0", "NAVL1_PERIOD = 17.0"))
    vehicle, gcs = start(vehicle_factory, state, config)
    assert read(gcs, "NAVL1_PERIOD") == 17.0
    assert read(gcs, "WP_RADIUS") == 45.0  # what the user set is kept
    # The controller, started in flight, reads its parameters as this does.
    decls = FixedWingPlugin.param_decls({}, {"airframe": str(airframe)})
    flying = LiveParams(vehicle.bus, decls, state)
    assert flying["NAVL1_PERIOD"] == 17.0 and flying["WP_RADIUS"] == 45.0
    assert json.loads((state / "params.json").read_text()) == {
        "format": 2,
        "set": {"WP_RADIUS": 45.0},
    }
    gcs.close()
