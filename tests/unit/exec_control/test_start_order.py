"""The order the supervisor starts plug-ins in: what a flight in the air waits for first."""

from __future__ import annotations

from companion.exec_control.child import Child
from companion.exec_control.config import load_config
from companion.exec_control.supervisor import Supervisor
from tests.support.vehicle import REPO

HIL = REPO / "companion" / "configs" / "hil.toml"


def test_the_flight_chain_and_what_it_needs_start_before_the_rest(monkeypatch):
    cfg = load_config(HIL)
    started: list[str] = []
    monkeypatch.setattr(Child, "start", lambda child: started.append(child.spec.name))
    supervisor = Supervisor(cfg)
    supervisor.start_group("core")
    # The IMU, GPS and navigator (the solution a restart in the air is judged by), the
    # commander (it judges, and arms again) and the link (its commands are the commander's
    # required input) first, each group in config order; the log and the slower sensors after.
    assert started == [
        "link", "gps", "imu", "rc", "nav", "commander", "compass", "battery", "range", "logger"
    ]  # fmt: skip
    supervisor.start_group("flight")
    assert started[-2:] == ["control", "servos"]
    # The health table keeps the config's order.
    assert [c.spec.name for c in supervisor.children] == [s.name for s in cfg.plugins]
