"""``companion hil``: the simulator alone, driving the vehicle's serial lines in real time.

Hardware in the loop: the vehicle runs apart (``companion run --config FILE`` on the
aircraft's computer, or in another shell) and reads these lines with its own drivers, as
it reads the real devices in the air; the simulator reads its Mini SSC bytes back and
moves JSBSim's surfaces. Its MAVLink goes where its own config says.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Annotated

import typer

from companion.cli.app import app, err
from ground.cli.extras import require_ground_extra
from ground.cli.flight_options import parse_home, parse_outage, parse_triple


def _line(device: str) -> object:
    return typer.Option(
        f"--{device}", help=f"the {device} line: /dev/ttyX[:BAUD], pty:PATH or a pyserial URL"
    )


def _lines(ptys: Path | None, named: dict[str, str | None]) -> dict[str, str]:
    """Every device on a pty under ``ptys`` (if given), then the lines named one by one."""
    from bridges.jsbsim.options import DEVICES

    lines = {name: f"pty:{ptys / name}" for name in DEVICES} if ptys else {}
    lines.update({name: spec for name, spec in named.items() if spec})
    if not lines:
        raise typer.BadParameter("name the lines: --ptys DIR, or --gps/--imu/.../--servos")
    return lines


@app.command()
def hil(
    gps: Annotated[str | None, _line("gps")] = None,
    compass: Annotated[str | None, _line("compass")] = None,
    imu: Annotated[str | None, _line("imu")] = None,
    servos: Annotated[str | None, _line("servos")] = None,
    rc: Annotated[str | None, _line("rc")] = None,
    battery: Annotated[str | None, _line("battery")] = None,
    range_: Annotated[str | None, _line("range")] = None,
    ptys: Annotated[
        Path | None,
        typer.Option(help="every device on a pty linked at DIR/<device> (one-machine trial)"),
    ] = None,
    aircraft: Annotated[str, typer.Option(help="airframe: c172p, J3Cub, or a TOML path")] = "c172p",
    home: Annotated[
        str | None, typer.Option(help="LAT,LON[,GROUND_MSL_M[,HEADING_DEG]] of the start")
    ] = None,
    airborne: Annotated[bool, typer.Option(help="start in the air at cruise speed")] = False,
    wind: Annotated[str, typer.Option(help="steady wind N,E,D m/s (blowing towards)")] = "0,0,0",
    turbulence: Annotated[str, typer.Option(help="none, light, moderate, severe")] = "none",
    gps_outage: Annotated[
        list[str] | None, typer.Option(help="START:SECONDS of no GPS fix, repeatable")
    ] = None,
    duration: Annotated[float | None, typer.Option(help="seconds to fly, then stop")] = None,
    seed: Annotated[
        int,
        typer.Option(help="sensor noise and turbulence seed (0 and 1: JSBSim's own gusts)"),
    ] = 1,
    noise: Annotated[float, typer.Option(help="sensor noise scale (0: perfect)")] = 1.0,
    gps_wander: Annotated[
        float | None, typer.Option(min=0, max=100, help="the GPS's wandering error, m")
    ] = None,
    gps_receiver: Annotated[
        str, typer.Option("--gps-receiver", help="standard, rtk, rtk-mavlink")
    ] = "standard",
    mount: Annotated[str, typer.Option(help="calibrated, uncalibrated, quiet")] = "calibrated",
    imu_hz: Annotated[float, typer.Option(min=5, max=400, help="IMU output rate")] = 100.0,
    gps_hz: Annotated[float, typer.Option(min=0.2, max=20, help="GPS fixes a second")] = 5.0,
    truth: Annotated[Path | None, typer.Option(help="write the true state CSV here")] = None,
    pilot: Annotated[
        Path | None, typer.Option(help="scripted RC pilot CSV (on the --rc line)")
    ] = None,
    servo_log: Annotated[
        Path | None, typer.Option(help="write the surface commands received (CSV) here")
    ] = None,
) -> None:
    """Fly JSBSim in real time with its devices on serial lines to a vehicle running apart.

    Start the vehicle with its own config (device paths = the other ends of these lines);
    arm and fly it from the ground station as in the field.
    """
    require_ground_extra("hil", "jsbsim")
    from bridges.jsbsim.options import BridgeOptions, DeviceRates

    named = {"gps": gps, "compass": compass, "imu": imu, "servos": servos, "rc": rc}
    named |= {"battery": battery, "range": range_}
    try:
        opts = BridgeOptions(
            airframe=aircraft, home=parse_home(home), airborne=airborne, speed=1.0,
            wind_ned=parse_triple(wind), turbulence=turbulence,
            outages=[parse_outage(o) for o in gps_outage or []], noise_scale=noise,
            seed=seed, gps_wander_m=gps_wander, gps=gps_receiver, mount=mount,
            rates=DeviceRates(imu_hz=imu_hz, gps_hz=gps_hz), duration_s=duration,
            truth_path=str(truth) if truth else None,
            pilot_path=str(pilot) if pilot else None,
            servo_log_path=str(servo_log) if servo_log else None,
            lines=_lines(ptys, named),
        )  # fmt: skip
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    err.print(f"hardware in the loop: {', '.join(f'{k} {v}' for k, v in opts.lines.items())}")
    sys.stdout.flush()
    sys.stderr.flush()
    # The bridge's own process image: the command line's libraries are not carried along.
    argv = [sys.executable, "-m", "bridges.jsbsim", opts.to_json()]
    os.execv(sys.executable, argv)
