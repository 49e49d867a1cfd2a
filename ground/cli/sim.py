"""``companion sim``: one vehicle, or a fleet, flying in JSBSim."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, NoReturn

import typer

from companion.cli.app import (
    CONFIG_OPT,
    EXIT_CONFIG,
    NS_OPT,
    app,
    err,
    plan_or_exit,
)
from companion.exec_control.vehicle_process import setup_logging
from ground.cli.extras import require_ground_extra
from ground.cli.flight_options import parse_home as _home
from ground.cli.flight_options import parse_outage as _outage
from ground.cli.flight_options import parse_triple as _triple

CONFIGS = Path(__file__).resolve().parents[2] / "companion" / "configs"


def _speed(text: str) -> float | None:
    if text == "max":
        return None
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if value <= 0:
        raise typer.BadParameter("1 (real time), a factor such as 4, or max (lockstep)")
    return value


def _single_links(link: list[str] | None, api_port_base: int | None) -> list[str]:
    """One vehicle: ``--link`` replaces the config's endpoints, as always; an explicit
    ``--api-port-base`` adds the API port (and the default ground station if no ``--link``)."""
    from ground.sitl.requests import GCS_LINK

    links = list(link or [])
    if api_port_base is not None:
        links = links or [GCS_LINK]
        links += [f"udpout://127.0.0.1:{api_port_base}"] if api_port_base else []
    return links


def _check_links(links: list[str]) -> None:
    """Refuse a --link the link could not open, before anything flies without it."""
    from companion.link.endpoint_urls import url_problem

    for url in links:
        if (problem := url_problem(url)) is not None:
            raise typer.BadParameter(problem, param_hint="--link")


def _fleet_settings(config: Path, namespace: str) -> tuple[dict, dict]:
    from rich.markup import escape

    from companion.exec_control.config import ConfigError, load_sections

    try:
        return load_sections(config, namespace)
    except ConfigError as exc:
        err.print(f"[red]config error:[/red] {escape(str(exc))}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None


def _run_fleet(req) -> int:
    from ground.sitl.fleet import Fleet

    try:
        fleet = Fleet(req)
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    return fleet.run()


def _run_one(req, opts, log_level: str, logs_dir: Path, truth: Path | None) -> NoReturn:
    """One vehicle, flown on in this process without the command line's libraries."""
    from companion.exec_control.handover import exec_module

    exec_module("ground.sitl.session_process", (req, opts, log_level, logs_dir, truth))


@app.command()
def sim(
    aircraft: Annotated[
        str | None,
        typer.Option(
            help="airframe: c172p, J3Cub, or a TOML path (default: the \\[vehicle] airframe)"
        ),
    ] = None,
    plan: Annotated[Path | None, typer.Option(help="QGroundControl .plan to preload")] = None,
    speed: Annotated[str, typer.Option(help="1 = real time, N = N times, max = lockstep")] = "1",
    link: Annotated[
        list[str] | None,
        typer.Option(help="MAVLink endpoint URL, repeatable (default udpout 14550 and 14540)"),
    ] = None,
    airborne: Annotated[bool, typer.Option(help="start in the air at cruise speed")] = False,
    airborne_bank: Annotated[
        float, typer.Option(min=-80, max=80, help="with --airborne: start banked (deg)")
    ] = 0.0,
    wind: Annotated[str, typer.Option(help="steady wind N,E,D m/s (blowing towards)")] = "0,0,0",
    turbulence: Annotated[str, typer.Option(help="none, light, moderate, severe")] = "none",
    gps_outage: Annotated[
        list[str] | None, typer.Option(help="START:SECONDS of no GPS fix, repeatable")
    ] = None,
    duration: Annotated[float | None, typer.Option(help="simulated seconds, then stop")] = None,
    seed: Annotated[
        int,
        typer.Option(help="sensor noise and turbulence seed (0 and 1: JSBSim's own gusts)"),
    ] = 1,
    exact: Annotated[
        bool,
        typer.Option(
            "--exact/--fast",
            help="lockstep: also wait for the control loop each step (same seed, same flight;"
            " about half the speed)",
        ),
    ] = False,
    start_at: Annotated[
        float | None,
        typer.Option(
            min=0,
            help="arm and start the mission at this simulated second, holding the simulation"
            " for both acks (every run starts at the same frame)",
        ),
    ] = None,
    hold_at: Annotated[
        float | None,
        typer.Option(
            min=0,
            help="hold the simulation at this simulated second until a ground station has"
            " armed the vehicle and started its mission (with --exact, a flight flown from a"
            " ground station repeats to the frame)",
        ),
    ] = None,
    noise: Annotated[float, typer.Option(help="sensor noise scale (0: perfect)")] = 1.0,
    gps_wander: Annotated[
        float | None,
        typer.Option(
            min=0,
            max=100,
            help="the GPS's slowly wandering error, m per axis (default: the receiver "
            "model's 1 m; 0: only its white noise)",
        ),
    ] = None,
    gps_receiver: Annotated[
        str,
        typer.Option(
            help="the GPS receiver: standard (a consumer receiver, about 1 m of error per"
            " axis), rtk (RTK fixed on corrections of its own: about 1 cm), rtk-mavlink (RTK"
            " while the vehicle passes it the ground station's GPS_RTCM_DATA: float for its"
            " first 8 s, then fixed)"
        ),
    ] = "standard",
    mount: Annotated[
        str,
        typer.Option(
            help="the sensors' airframe defects: calibrated (a good compass calibration's "
            "residue, about 2 degrees), uncalibrated, quiet (none)"
        ),
    ] = "calibrated",
    imu_hz: Annotated[float, typer.Option(min=5, max=400, help="IMU output rate")] = 100.0,
    truth: Annotated[Path | None, typer.Option(help="write the true state CSV here")] = None,
    pilot: Annotated[
        Path | None,
        typer.Option(help="scripted RC pilot: CSV t,roll,pitch,yaw,throttle,switch,signal"),
    ] = None,
    servo_log: Annotated[
        Path | None, typer.Option(help="write the surface commands received (CSV) here")
    ] = None,
    config: Annotated[Path, CONFIG_OPT] = CONFIGS / "sim.toml",
    namespace: Annotated[str | None, NS_OPT] = None,
    state_dir: Annotated[str | None, typer.Option(help="parameters and missions dir")] = None,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "INFO",
    home: Annotated[
        str | None, typer.Option(help="LAT,LON[,GROUND_MSL_M[,HEADING_DEG]] of the start")
    ] = None,
    sysid: Annotated[
        int | None, typer.Option(min=1, max=255, help="MAVLink system id (default: config)")
    ] = None,
    count: Annotated[
        int | None, typer.Option(min=1, max=254, help="vehicles to fly (default: \\[fleet] or 1)")
    ] = None,
    spacing: Annotated[
        float | None, typer.Option(min=0, help="metres east between vehicles (default 50)")
    ] = None,
    api_port_base: Annotated[
        int | None,
        typer.Option(min=0, max=65535, help="vehicle i also sends to udpout 14540+i-1; 0: none"),
    ] = None,
) -> None:
    """Fly the whole vehicle in JSBSim: devices on ptys, servos read back, MAVLink out.

    With --count N, N vehicles: sysid i, bus NAMESPACE_v<i>, state STATE_DIR/v<i>, each
    (i-1)*spacing m east of home, all on the --link endpoints, each on its own API port.
    """
    require_ground_extra("sim", "jsbsim")
    from bridges.jsbsim.options import BridgeOptions, DeviceRates
    from companion.bus.namespace import default_namespace
    from ground.sitl.requests import GCS_LINK, FleetRequest, SimRequest

    setup_logging(log_level)
    _check_links(link or [])
    lists = plan_or_exit(plan) if plan is not None else None
    vehicle, fleet = _fleet_settings(config, namespace or default_namespace())
    try:
        opts = BridgeOptions(
            airframe=aircraft or vehicle["airframe"], home=_home(home), airborne=airborne,
            speed=_speed(speed),
            wind_ned=_triple(wind), turbulence=turbulence,
            outages=[_outage(o) for o in gps_outage or []], noise_scale=noise, seed=seed,
            gps_wander_m=gps_wander, gps=gps_receiver,
            mount=mount, airborne_bank_deg=airborne_bank,
            rates=DeviceRates(imu_hz=imu_hz),
            exact=exact, start_at_s=start_at, hold_at_s=hold_at,
            duration_s=duration, truth_path=str(truth) if truth else None,
            pilot_path=str(pilot) if pilot else None,
            servo_log_path=str(servo_log) if servo_log else None,
            namespace=namespace or default_namespace(),
        )  # fmt: skip
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    count = count if count is not None else fleet["count"]
    if count > 1:
        if sysid is not None:
            raise typer.BadParameter("a fleet's vehicles are sysid 1..N; --sysid is for one")
        if pilot is not None or servo_log is not None:
            raise typer.BadParameter("--pilot and --servo-log are for one vehicle")
        raise typer.Exit(_run_fleet(FleetRequest(
            count=count, opts=opts, config=config, links=list(link or [GCS_LINK]),
            state_dir=Path(state_dir or vehicle["state_dir"]).expanduser(),
            spacing_m=fleet["spacing_m"] if spacing is None else spacing,
            api_port_base=fleet["api_port_base"] if api_port_base is None else api_port_base,
            plan=plan, log_level=log_level,
        )))  # fmt: skip
    req = SimRequest(config, _single_links(link, api_port_base), state_dir, lists, sysid)
    logs_dir = Path(state_dir or vehicle["state_dir"]).expanduser() / "logs"
    _run_one(req, opts, log_level, logs_dir, truth)
