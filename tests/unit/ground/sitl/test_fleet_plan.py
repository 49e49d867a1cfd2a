"""What ``companion sim --count N`` gives each vehicle, and the config's ``[fleet]`` table."""

from __future__ import annotations

import dataclasses
import pickle
from pathlib import Path

import pytest
from typer.testing import CliRunner

from bridges.jsbsim.device_streams import Outage
from bridges.jsbsim.options import BridgeOptions
from companion.cli import app
from companion.exec_control.config import ConfigError, load_config, load_sections
from companion.geodesy import LocalFrame
from ground.sitl.fleet import FleetRequest, plan_slots, shared_args, vehicle_command
from tests.support.vehicle import REPO

SIM_TOML = REPO / "companion" / "configs" / "sim.toml"


def request(tmp_path: Path, **changes) -> FleetRequest:
    opts = BridgeOptions(
        airframe="J3Cub", speed=None, wind_ned=(5.0, 0.0, 0.0), turbulence="light",
        outages=[Outage(60.0, 30.0)], seed=7, duration_s=120.0, namespace="fl",
        truth_path=str(tmp_path / "truth.csv"), airborne=True, exact=True, start_at_s=20.0,
    )  # fmt: skip
    req = FleetRequest(
        count=3, opts=opts, config=SIM_TOML, state_dir=tmp_path / "state",
        links=["udpout://127.0.0.1:14550"], plan=REPO / "qgc_plans" / "loiter.plan",
    )  # fmt: skip
    return dataclasses.replace(req, **changes)


def test_each_vehicle_has_its_own_identity_ports_home_and_files(tmp_path):
    slots = plan_slots(request(tmp_path))
    assert [s.index for s in slots] == [1, 2, 3]
    assert [s.namespace for s in slots] == ["fl_v1", "fl_v2", "fl_v3"]
    assert [s.state_dir.name for s in slots] == ["v1", "v2", "v3"]
    assert [s.log_path for s in slots] == [s.state_dir / "sim.log" for s in slots]
    assert [s.truth.name for s in slots] == ["truth_v1.csv", "truth_v2.csv", "truth_v3.csv"]
    assert [s.seed for s in slots] == [7, 8, 9]
    apis = [f"udpout://127.0.0.1:{port}" for port in (14540, 14541, 14542)]
    assert [s.links[-1] for s in slots] == apis
    assert all(s.links[0] == "udpout://127.0.0.1:14550" for s in slots)
    frame = LocalFrame(slots[0].home.lat_deg, slots[0].home.lon_deg)
    offsets = [frame.ne(s.home.lat_deg, s.home.lon_deg) for s in slots]
    assert offsets == [pytest.approx((0.0, e), abs=1e-6) for e in (0.0, 50.0, 100.0)]
    assert {s.home.heading_deg for s in slots} == {90.0}


def test_no_api_port_and_impossible_fleets(tmp_path):
    assert all(len(s.links) == 1 for s in plan_slots(request(tmp_path, api_port_base=0)))
    with pytest.raises(ValueError, match="past 65535"):
        plan_slots(request(tmp_path, api_port_base=65534))
    opts = dataclasses.replace(request(tmp_path).opts, namespace="n" * 38)
    with pytest.raises(ValueError, match="namespace"):
        plan_slots(request(tmp_path, opts=opts))


def test_the_vehicle_command_line_means_what_the_fleet_planned(tmp_path, monkeypatch):
    """Run a vehicle's command line through the CLI: it hands exactly that vehicle over to
    the process that flies it."""
    req = request(tmp_path)
    slot = plan_slots(req)[1]
    seen = {}

    def fake_exec_module(module, payload):
        sim_req, opts, _log_level, _logs_dir, _truth = pickle.loads(pickle.dumps(payload))
        seen.update(module=module, req=sim_req, opts=opts)
        raise SystemExit(0)

    monkeypatch.setattr("companion.exec_control.handover.exec_module", fake_exec_module)
    argv = vehicle_command(slot, shared_args(req))[3:]  # after "python -m companion"
    result = CliRunner().invoke(app, argv)
    assert result.exit_code == 0, result.output
    want = dataclasses.replace(
        req.opts, home=slot.home, seed=8, namespace="fl_v2", truth_path=str(slot.truth)
    )
    assert seen["module"] == "ground.sitl.session_process"
    assert seen["opts"] == want
    assert seen["req"].sysid == 2 and seen["req"].links == slot.links
    assert seen["req"].state_dir == str(slot.state_dir) and seen["req"].plan is not None


def test_the_fleet_table_is_checked_and_ignored_by_run(tmp_path):
    vehicle, fleet = load_sections(SIM_TOML, "fl")
    assert vehicle["sysid"] == 1 and vehicle["state_dir"].endswith("/sim/fl")
    assert fleet == {"count": 1, "spacing_m": 50.0, "api_port_base": 14540}
    config = tmp_path / "v.toml"
    config.write_text('[vehicle]\nname = "v"\n\n[fleet]\ncount = 2\ncuont = 3\n')
    with pytest.raises(ConfigError) as err:
        load_config(config)
    assert err.value.key == "fleet.cuont" and err.value.line == 6
    assert "did you mean 'count'" in str(err.value) and str(config) in str(err.value)
    config.write_text('[vehicle]\nname = "v"\n\n[fleet]\ncount = 2\nspacing_m = 30\n')
    assert load_config(config).fleet == {"count": 2, "spacing_m": 30.0, "api_port_base": 14540}
    config.write_text("[fleet]\ncount = 0\n")
    with pytest.raises(ConfigError, match="below the minimum 1"):
        load_sections(config)


def test_a_fleet_refuses_what_is_for_one_vehicle(tmp_path):
    pilot = tmp_path / "pilot.csv"
    pilot.write_text("t,roll,pitch,yaw,throttle,switch,signal\n")
    result = CliRunner().invoke(app, ["sim", "--count", "2", "--pilot", str(pilot)])
    assert result.exit_code == 2 and "for one vehicle" in result.output


def test_sim_refuses_a_misspelt_fleet_key_before_starting_anything(tmp_path):
    config = tmp_path / "sim.toml"
    config.write_text(SIM_TOML.read_text().replace("spacing_m =", "spaceing_m ="))
    result = CliRunner().invoke(app, ["sim", "--config", str(config)])
    assert result.exit_code == 2
    assert "fleet.spaceing_m" in result.output and "did you mean 'spacing_m'" in result.output


def test_two_vehicles_of_one_config_never_share_a_default_state_dir():
    one, _ = load_sections(SIM_TOML, "alpha")
    two, _ = load_sections(SIM_TOML, "bravo")
    assert one["state_dir"] != two["state_dir"]
    refs = {
        name: "/dev/null" for name in ("gps", "compass", "imu", "rc", "range", "battery", "servos")
    }
    config = load_config(SIM_TOML, "bravo", sim_refs=refs)
    assert config.vehicle["state_dir"] == two["state_dir"]
