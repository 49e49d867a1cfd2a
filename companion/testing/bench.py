"""The bench vehicle: ``companion run`` with its sensors replayed from a recorded log
(``sensors.replay``), the GPS-compass navigator, the commander and the MAVLink link; no
simulator, nothing that moves. It answers every ground tool (parameters, missions,
fences, logs, commands) with the position and attitude the log says, and records a flight
log (``system.logger``) from each arming to its disarming, as the aircraft does.

Its pre-arm checks are off (``ARMING_CHECK`` 0), as on a bench: the replayed samples keep
the log's time stamps, which are not the vehicle clock's, so none would ever look fresh.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from companion.testing.loopback import LoopbackVehicle, companion_command
from companion.testing.options import VehicleOptions

HOME = (-37.9105, 145.1340)  # the sample circle's start (the simulator's default home)


def write_circle_log(path: Path, seconds: float = 120.0, home: tuple[float, float] = HOME) -> Path:
    """A sensor log (the design's CSV) of a 190 m circle at 20 m/s: compass at 20 Hz
    (rolling, pitching, turning through north), GPS at 5 Hz."""
    header = "t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m,"
    lines = [header + "heading_deg,pitch_deg,roll_deg"]
    per_deg_lon = 111_320.0 * math.cos(math.radians(home[0]))
    for i in range(int(seconds * 20)):
        t = i * 0.05
        heading = (300.0 + 6.0 * t) % 360.0
        roll, pitch = 30.0 * math.sin(0.7 * t), -8.0 * math.cos(0.4 * t)
        lines.append(f"{t:.2f},compass,,,,,,,,,,,,,,,,,,,{heading:.2f},{pitch:.2f},{roll:.2f}")
        if i % 4 == 0:
            a = math.radians(6.0 * t)
            lat = home[0] + 190.0 * math.sin(a) / 111_320.0
            lon = home[1] + 190.0 * (1 - math.cos(a)) / per_deg_lon
            vn, ve = 20.0 * math.cos(a), 20.0 * math.sin(a)
            lines.append(
                f"{t:.2f},gps,,,,,,,{lat:.8f},{lon:.8f},100,{vn:.2f},{ve:.2f},,3,0.8,,,,,,,"
            )
    path.write_text("\n".join(lines) + "\n")
    return path


def bench_config(vehicle: LoopbackVehicle, sensor_log: Path) -> str:
    """The vehicle's config file text (TOML)."""
    links = json.dumps(vehicle.ports.links(vehicle.tlog_path))
    airframe = vehicle.options.airframe or "J3Cub"
    return f"""\
[vehicle]
name = "bench"
sysid = 1
airframe = {json.dumps(airframe)}
state_dir = {json.dumps(str(vehicle.state_dir))}

[[plugins]]
name = "link"
plugin = "link.mavlink"
settings = {{ endpoints = {links} }}

[[plugins]]
name = "replay"
plugin = "sensors.replay"
settings = {{ file = {json.dumps(str(sensor_log))}, speed = 1.0, loop = true }}

[[plugins]]
name = "nav"
plugin = "nav.gps_compass"

[[plugins]]
name = "commander"
plugin = "vehicle.commander"

[[plugins]]
name = "logger"
plugin = "system.logger"
"""


def start_bench(
    folder: Path, options: VehicleOptions | None = None, pythonpath: tuple[Path, ...] = ()
) -> LoopbackVehicle:
    """``companion run`` on the bench config, on free ports, in ``folder``."""
    vehicle = LoopbackVehicle("bench", folder, options)
    opts = vehicle.options
    sensor_log = Path(opts.sensor_log or write_circle_log(folder / "sensors.csv"))
    checks = 1 if opts.arming_check else 0
    params = vehicle.state_dir / "params.json"
    if not params.exists():  # a test that stored its own parameters keeps them
        params.write_text(json.dumps({"ARMING_CHECK": checks}))
    config = folder / "bench.toml"
    config.write_text(bench_config(vehicle, sensor_log))
    command = companion_command("run", "-c", str(config), "-n", vehicle.namespace)
    try:
        return vehicle.start(command, pythonpath)
    except BaseException:
        vehicle.close()
        raise
