"""sensors.replay plays a log onto the bus in another process, with the log's times."""

from __future__ import annotations

import math

import pytest

from companion.messages import CommandId, NavFlags, VehicleCommand
from tests.support.configs import PluginEntry, plugin, vehicle_config
from tests.support.vehicle import wait_for

ROWS = 100


def replay(log, speed: float) -> PluginEntry:
    """The replay in the flight group: it starts only once the readers exist."""
    return plugin("replay", "sensors.replay", group="flight", file=log, speed=speed)


def make_log(path):
    lines = ["t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m"]
    for i in range(ROWS):
        lines.append(f"{i * 0.02:.3f},imu,{i},0,-9.81,0,0,0,,,,,,,,,,,,")
        if i % 10 == 0:
            lines.append(
                f"{i * 0.02:.3f},gps,,,,,,,-37.91,{145.134 + i * 1e-5:.5f},100,1,2,,3,1,,,,"
            )
    lines.append("9.99,bogus,,,,,,,,,,,,,,,,,,")
    path.write_text("\n".join(lines) + "\n")


def test_replay_publishes_every_sample_in_order_with_log_times(vehicle_factory, tmp_path):
    log = tmp_path / "flight.csv"
    make_log(log)
    vehicle = vehicle_factory(vehicle_config("replay", replay(log, 4.0)))
    imu = vehicle.bus.queue_reader("sensors/imu")
    gps = vehicle.bus.queue_reader("sensors/gps")
    commands = vehicle.bus.writer("link/commands")
    wait_for(vehicle.health, 60, "the health table")
    # The replay is in the flight group so it starts (START) only once the readers exist.
    commands.publish(VehicleCommand(t_us=0, seq=1, command=int(CommandId.START)))
    got_imu, got_gps = [], []

    def done() -> bool:
        got_imu.extend(imu.take(0.2))
        got_gps.extend(gps.take())
        return len(got_imu) >= ROWS

    wait_for(done, 20, "all IMU samples")
    assert [m.t_us for m in got_imu] == [i * 20_000 for i in range(ROWS)]
    assert [m.ax_m_s2 for m in got_imu] == [float(i) for i in range(ROWS)]
    assert len(got_gps) == ROWS // 10 and got_gps[1].lon_deg == 145.1341
    assert imu.lost == 0
    wait_for(lambda: vehicle.row("replay").frames_bad == 1, 5, "the bogus row counted")


def test_replayed_gps_and_compass_reach_nav_state_through_gps_compass(vehicle_factory, tmp_path):
    log = tmp_path / "flight.csv"
    header = "t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m,"
    lines = [header + "heading_deg,pitch_deg,roll_deg"]
    for i in range(100):
        t = i * 0.05
        if i % 4 == 0:
            lat = -37.91 + 20.0 * t / 111_320.0
            lines.append(f"{t:.2f},gps,,,,,,,{lat:.8f},145.134,100,20,0,,3,0.8,,,,,,,")
        lines.append(f"{t:.2f},compass,,,,,,,,,,,,,,,,,,,5.0,1.0,-2.0")
    log.write_text("\n".join(lines) + "\n")
    vehicle = vehicle_factory(
        vehicle_config("navchain", plugin("nav", "nav.gps_compass"), replay(log, 2.0))
    )
    nav = vehicle.bus.latest_reader("nav/state")
    # Start the replay only once the navigator has its inputs open (its first step done):
    # starting a plug-in process can take seconds on a loaded machine.
    wait_for(lambda: (r := vehicle.row("nav")) is not None and r.step_p50_us > 0, 30, "nav up")
    vehicle.bus.writer("link/commands").publish(
        VehicleCommand(t_us=0, seq=1, command=int(CommandId.START))
    )
    state = wait_for(
        lambda: (s := nav.wait(0.2)) is not None and s.t_us >= 4_800_000 and s, 15, "the end"
    )
    t = state.t_us / 1e6  # under load the newest value may be a later one than 4.8 s
    assert state.lat_deg == pytest.approx(-37.91 + 20.0 * t / 111_320.0, abs=2e-5)
    assert state.vn_m_s == pytest.approx(20.0, abs=0.5)
    assert state.yaw_rad == pytest.approx(math.radians(5.0))


def test_replayed_imu_gps_and_magnetometer_reach_nav_state_through_ins_ekf(
    vehicle_factory, tmp_path
):
    from ground.simulation.synthetic_flight import FlightSpec, Leg
    from ground.simulation.synthetic_log import synthesize

    log = tmp_path / "flight.csv"
    synthetic = synthesize(FlightSpec(legs=(Leg(12),), heading_deg=90.0, seed=2))
    synthetic.write(log)
    nav_plugin = plugin("nav", "nav.ins_ekf", declination_deg=11.7)
    vehicle = vehicle_factory(vehicle_config("inschain", nav_plugin, replay(log, 2.0)))
    nav = vehicle.bus.latest_reader("nav/state")
    wait_for(lambda: (r := vehicle.row("nav")) is not None and r.step_p50_us > 0, 30, "nav up")
    vehicle.bus.writer("link/commands").publish(
        VehicleCommand(t_us=0, seq=1, command=int(CommandId.START))
    )
    state = wait_for(
        lambda: (s := nav.wait(0.2)) is not None and s.t_us >= 11_000_000 and s, 30, "the end"
    )
    true = min(synthetic.truth, key=lambda s: abs(s.t_s - state.t_us / 1e6))
    assert state.flags & NavFlags.POSITION_VALID and state.flags & NavFlags.ATTITUDE_VALID
    assert math.degrees(state.yaw_rad) == pytest.approx(90.0, abs=2.0)
    assert state.lon_deg == pytest.approx(true.lon_deg, abs=5e-5)
    assert vehicle.row("nav").dropped == 0
