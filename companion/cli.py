"""The ``companion`` command: run a vehicle, look at it, check its config."""

from __future__ import annotations

import json
import logging
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="On-board software of a MAVLink-speaking fixed-wing UAV companion computer.",
)
err = Console(stderr=True)
# A pipe gets a wide console so the status table is not folded into unreadable columns.
out = Console() if sys.stdout.isatty() else Console(width=200)

CONFIG_OPT = typer.Option("--config", "-c", help="vehicle config (TOML)")
NS_OPT = typer.Option("--namespace", "-n", help="bus namespace (default: config or $COMPANION_BUS)")
EXIT_CONFIG = 2


def _setup_logging(level: str, who: str = "exec_control") -> None:
    logging.basicConfig(level=level, format=f"%(asctime)s {who} %(levelname)s %(message)s")


def _load_checked(config: Path, namespace: str | None):
    from companion.exec_control.config import ConfigError, load_config
    from companion.exec_control.topology import check_topology

    try:
        cfg = load_config(config, namespace)
        check_topology(cfg)
    except ConfigError as exc:
        err.print(f"[red]config error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    return cfg


@app.command()
def run(
    config: Annotated[Path, CONFIG_OPT],
    namespace: Annotated[str | None, NS_OPT] = None,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "INFO",
) -> None:
    """Run the vehicle: every plug-in of the config in its own process, supervised."""
    from companion.exec_control.supervisor import Supervisor

    _setup_logging(log_level)
    cfg = _load_checked(config, namespace)
    raise typer.Exit(Supervisor(cfg, log_level).run())


CONFIGS = Path(__file__).resolve().parent / "configs"


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


def _triple(text: str) -> tuple[float, float, float]:
    try:
        n, e, d = (float(v) for v in text.split(","))
    except ValueError:
        raise typer.BadParameter("expected N,E,D in m/s, e.g. 5,0,0") from None
    return n, e, d


def _outage(text: str):
    from bridges.jsbsim.device_streams import Outage

    try:
        start, seconds = (float(v) for v in text.split(":"))
    except ValueError:
        raise typer.BadParameter("expected START:SECONDS, e.g. 60:30") from None
    return Outage(start, seconds)


def _home(text: str | None):
    from bridges.jsbsim.fdm import Home

    if text is None:
        return Home()
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not 2 <= len(values) <= 4:
        raise typer.BadParameter("expected LAT,LON[,GROUND_MSL_M[,HEADING_DEG]]")
    names = ("lat_deg", "lon_deg", "ground_msl_m", "heading_deg")
    return Home(**dict(zip(names, values, strict=False)))


def _single_links(link: list[str] | None, api_port_base: int | None) -> list[str]:
    """One vehicle: ``--link`` replaces the config's endpoints, as always; an explicit
    ``--api-port-base`` adds the API port (and the default ground station if no ``--link``)."""
    from companion.fleet import GCS_LINK

    links = list(link or [])
    if api_port_base is not None:
        links = links or [GCS_LINK]
        links += [f"udpout://127.0.0.1:{api_port_base}"] if api_port_base else []
    return links


def _fleet_settings(config: Path) -> tuple[dict, dict]:
    from companion.exec_control.config import ConfigError, load_sections

    try:
        return load_sections(config)
    except ConfigError as exc:
        err.print(f"[red]config error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None


def _run_fleet(req) -> int:
    from companion.fleet import Fleet

    try:
        fleet = Fleet(req)
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    return fleet.run()


@app.command()
def sim(
    aircraft: Annotated[str, typer.Option(help="airframe: c172p, J3Cub, or a TOML path")] = "c172p",
    plan: Annotated[Path | None, typer.Option(help="QGroundControl .plan to preload")] = None,
    speed: Annotated[str, typer.Option(help="1 = real time, N = N times, max = lockstep")] = "1",
    link: Annotated[
        list[str] | None,
        typer.Option(help="MAVLink endpoint URL, repeatable (default udpout 14550 and 14540)"),
    ] = None,
    airborne: Annotated[bool, typer.Option(help="start in the air at cruise speed")] = False,
    wind: Annotated[str, typer.Option(help="steady wind N,E,D m/s (blowing towards)")] = "0,0,0",
    turbulence: Annotated[str, typer.Option(help="none, light, moderate, severe")] = "none",
    gps_outage: Annotated[
        list[str] | None, typer.Option(help="START:SECONDS of no GPS fix, repeatable")
    ] = None,
    duration: Annotated[float | None, typer.Option(help="simulated seconds, then stop")] = None,
    seed: Annotated[int, typer.Option(help="sensor noise seed")] = 1,
    noise: Annotated[float, typer.Option(help="sensor noise scale (0: perfect)")] = 1.0,
    truth: Annotated[Path | None, typer.Option(help="write the true state CSV here")] = None,
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
        int | None, typer.Option(min=1, max=254, help="vehicles to fly (default: [fleet] or 1)")
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
    from bridges.jsbsim.options import BridgeOptions
    from companion.bus.namespace import default_namespace
    from companion.exec_control.config import ConfigError
    from companion.fleet import GCS_LINK, FleetRequest
    from companion.sim_session import SimRequest, run_sim

    _setup_logging(log_level)
    lists = _checked_plan(plan) if plan is not None else None
    vehicle, fleet = _fleet_settings(config)
    try:
        opts = BridgeOptions(
            airframe=aircraft, home=_home(home), airborne=airborne, speed=_speed(speed),
            wind_ned=_triple(wind), turbulence=turbulence,
            outages=[_outage(o) for o in gps_outage or []], noise_scale=noise, seed=seed,
            duration_s=duration, truth_path=str(truth) if truth else None,
            namespace=namespace or default_namespace(),
        )  # fmt: skip
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    count = count if count is not None else fleet["count"]
    if count > 1:
        if sysid is not None:
            raise typer.BadParameter("a fleet's vehicles are sysid 1..N; --sysid is for one")
        raise typer.Exit(_run_fleet(FleetRequest(
            count=count, opts=opts, config=config, links=list(link or [GCS_LINK]),
            state_dir=Path(state_dir or vehicle["state_dir"]).expanduser(),
            spacing_m=fleet["spacing_m"] if spacing is None else spacing,
            api_port_base=fleet["api_port_base"] if api_port_base is None else api_port_base,
            plan=plan, log_level=log_level,
        )))  # fmt: skip
    req = SimRequest(config, _single_links(link, api_port_base), state_dir, lists, sysid)
    try:
        code = run_sim(req, opts, log_level)
    except ConfigError as exc:
        err.print(f"[red]config error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    raise typer.Exit(code)


@app.command()
def graph(
    config: Annotated[Path, CONFIG_OPT],
    namespace: Annotated[str | None, NS_OPT] = None,
) -> None:
    """Check a config and print its channel graph (who writes and reads each channel)."""
    from companion.exec_control.topology import graph_lines

    cfg = _load_checked(config, namespace)
    out.print(f"{cfg.path}: vehicle {cfg.name!r}, sysid {cfg.sysid}, bus {cfg.namespace!r}")
    for spec in cfg.plugins:
        out.print(f"  {spec.name:16} {spec.kind:28} {spec.group}")
    for line in graph_lines(cfg):
        out.print(line, highlight=False)


@app.command()
def status(
    namespace: Annotated[str | None, NS_OPT] = None,
    as_json: Annotated[bool, typer.Option("--json", help="machine-readable output")] = False,
    timeout: Annotated[float, typer.Option(help="seconds to wait for the table")] = 3.0,
) -> None:
    """Print the health table of a running vehicle (read from its bus)."""
    from companion.bus import default_namespace
    from companion.status_view import health_dict, health_table, read_health

    ns = namespace or default_namespace()
    msg = read_health(ns, timeout)
    if msg is None:
        err.print(f"no vehicle is publishing system/health on bus {ns!r}")
        raise typer.Exit(1)
    if as_json:
        sys.stdout.write(json.dumps(health_dict(msg), indent=2) + "\n")
    else:
        out.print(health_table(msg))


bridge_app = typer.Typer(help="Bridges between the vehicle and something outside it.")
app.add_typer(bridge_app, name="bridge")


@bridge_app.command("legacy-text")
def bridge_legacy_text(
    serial: Annotated[str, typer.Option(help="the 25-byte text link: path, pyserial URL")],
    mavlink: Annotated[str, typer.Option(help="the vehicle: udpin://, udpout://, tcp://...")],
    baud: Annotated[int, typer.Option(help="the text link's baud rate")] = 9600,
    att_rate: Annotated[float, typer.Option(help="ATT frames a second (0: none)")] = 10.0,
    pos_rate: Annotated[float, typer.Option(help="POS frames a second (0: none)")] = 4.0,
    start_mission: Annotated[bool, typer.Option(help="START also starts the mission")] = False,
    force_stop: Annotated[bool, typer.Option(help="STOP disarms even in the air")] = False,
    sysid: Annotated[int, typer.Option(help="the bridge's own MAVLink system id")] = 250,
    target_system: Annotated[int, typer.Option(help="the vehicle's system id (0: any)")] = 0,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "INFO",
) -> None:
    """The thesis's 25-byte text link (ATT, POS down; START, STOP up) on a serial line."""
    from bridges.legacy_text.bridge import LegacyTextOptions, serve

    logging.basicConfig(level=log_level, format="%(asctime)s legacy_text %(levelname)s %(message)s")
    opts = LegacyTextOptions(
        serial, mavlink, baud, att_rate, pos_rate, start_mission, force_stop, sysid, target_system
    )
    try:
        opts.check()
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    raise typer.Exit(serve(opts))


params_app = typer.Typer(help="Parameters in QGroundControl .params files (vehicle stopped).")
app.add_typer(params_app, name="params")


@app.command()
def replay(
    logs: Annotated[
        list[str],
        typer.Argument(
            metavar="LOG",
            help="sensor log CSVs (the design's format), folders of them or quoted patterns",
        ),
    ],
    out_path: Annotated[
        Path, typer.Option("--out", "-o", help="estimate CSV to write (a directory for many logs)")
    ],
    navigator: Annotated[str, typer.Option(help="ins_ekf or gps_compass")] = "ins_ekf",
    plot: Annotated[
        Path | None, typer.Option(help="also draw the flight into this PNG (many: a directory)")
    ] = None,
    truth: Annotated[Path | None, typer.Option(help="truth CSV to draw beside it")] = None,
    rate: Annotated[float, typer.Option(help="estimate rows per second of log time")] = 50.0,
    declination: Annotated[
        float, typer.Option(help="magnetic declination, degrees east (compass, magnetometer)")
    ] = 0.0,
    address: Annotated[
        str | None, typer.Option(help="many logs: Ray cluster address (default: local)")
    ] = None,
    cpus: Annotated[int | None, typer.Option(help="many logs: CPUs of the local Ray")] = None,
) -> None:
    """Run a navigator over recorded sensor logs, offline, as fast as it goes.

    Several logs, a folder or a pattern run on Ray; --out is then a directory.
    """
    from companion.estimation.offline import NAVIGATORS
    from companion.replay_batch import is_batch

    if navigator not in NAVIGATORS:
        raise typer.BadParameter(f"navigator must be one of {', '.join(NAVIGATORS)}")
    _setup_logging("WARNING")
    if is_batch(logs):
        if truth is not None:
            raise typer.BadParameter("--truth goes with a single log")
        _replay_batch(logs, out_path, navigator, plot, rate, declination, address, cpus)
    else:
        _replay_one(Path(logs[0]), out_path, navigator, plot, truth, rate, declination)


def _replay_one(
    log: Path, out_path: Path, navigator: str, plot: Path | None, truth: Path | None,
    rate: float, declination: float,
) -> None:  # fmt: skip
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from companion.replay import count_rows, replay_log

    if not log.is_file():
        err.print(f"[red]{log}: no such file[/red]", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG)
    fixes: list = []
    percent = TextColumn("{task.percentage:>3.0f}%")
    columns = (TextColumn("{task.description}"), BarColumn(), percent, TimeRemainingColumn())
    with Progress(*columns, console=err, transient=True) as bar:
        task = bar.add_task(f"{navigator} over {log.name}", total=count_rows(log))
        try:
            summary, states = replay_log(
                log, navigator, out_path, rate, declination,
                lambda n: bar.advance(task, n), fixes if plot else None,
            )  # fmt: skip
        except ValueError as exc:
            err.print(f"[red]{exc}[/red]", highlight=False, soft_wrap=True)
            raise typer.Exit(EXIT_CONFIG) from None
    _print_replay_summary(summary)
    if plot is not None:
        from companion.estimation.estimate_csv import read_estimate
        from companion.replay_plot import plot_replay

        plot_replay(states, plot, f"{log.name}: {navigator}", fixes,
                    read_estimate(truth) if truth else None)  # fmt: skip
        err.print(f"plot written to {plot}")


def _replay_batch(
    args: list[str], out_dir: Path, navigator: str, plot: Path | None, rate: float,
    declination: float, address: str | None, cpus: int | None,
) -> None:  # fmt: skip
    from companion.replay_batch import (
        SUMMARY_NAME,
        LogsError,
        find_logs,
        replay_logs,
        summary_table,
    )  # fmt: skip

    try:
        logs = find_logs(args, out_dir)
    except LogsError as exc:
        err.print(f"[red]{exc}[/red]", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    rows = replay_logs(logs, out_dir, navigator, rate, declination, plot, address, cpus, err)
    out.print(summary_table(rows, f"{navigator} over {len(rows)} logs"))
    failed = sum(1 for r in rows if r.error)
    out.print(f"{len(rows) - failed} ok, {failed} failed; summary {out_dir / SUMMARY_NAME}")
    raise typer.Exit(1 if failed else 0)


def _print_replay_summary(s) -> None:
    out.print(
        f"{s.log}: {s.rows} rows ({s.bad_rows} bad), {s.log_seconds:.1f} s of log in "
        f"{s.wall_seconds:.1f} s ({s.speed:.0f}x) -> {s.estimates} estimates"
    )
    out.print(
        f"innovation rejections: GPS {s.gps_rejected}, heading {s.heading_rejected}; "
        f"longest GPS gap {s.longest_outage_s:.1f} s; final horizontal 1-sigma "
        f"{s.final_pos_std_m:.1f} m; samples flagged {s.flagged}"
    )


def _param_store(config: Path, namespace: str | None):
    from companion.params import ParamStore

    cfg = _load_checked(config, namespace)
    decls = [d for spec in cfg.plugins for d in spec.params]
    return cfg, ParamStore(decls, Path(cfg.vehicle["state_dir"]) / "params.json")


@params_app.command("save")
def params_save(
    file: Annotated[Path, typer.Argument(help=".params file to write")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Write the vehicle's stored parameters to a .params file."""
    from companion.params.qgc_file import save_params

    cfg, store = _param_store(config, None)
    save_params(store, file, sysid=cfg.sysid)
    out.print(f"{len(store)} parameters written to {file}")


@params_app.command("load")
def params_load(
    file: Annotated[Path, typer.Argument(help=".params file to read")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Check a .params file against the config's declarations and store it (all or nothing)."""
    from companion.params import ParamError
    from companion.params.qgc_file import load_params

    _, store = _param_store(config, None)
    try:
        count = load_params(store, file)
    except (ParamError, OSError) as exc:
        err.print(f"[red]params error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    out.print(f"{count} parameters loaded from {file} into {store.path}")


mission_app = typer.Typer(help="Missions in QGroundControl .plan files (vehicle stopped).")
app.add_typer(mission_app, name="mission")


def _mission_store(config: Path):
    from companion.mission.store import MissionStore

    cfg = _load_checked(config, None)
    return MissionStore(Path(cfg.vehicle["state_dir"]) / "missions")


def _checked_plan(plan: Path):
    from companion.mission.plan import PlanError, checked_plan

    try:
        return checked_plan(plan)
    except PlanError as exc:
        err.print(f"[red]plan error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None


@mission_app.command("load")
def mission_load(
    plan: Annotated[Path, typer.Argument(help=".plan file to store as the vehicle's mission")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Check a .plan (mission, fence, rally) and store it; all or nothing."""
    store = _mission_store(config)
    lists = _checked_plan(plan)
    for mission_type, items in lists.items():
        store.replace(mission_type, items)
    counts = ", ".join(
        f"{len(v)} {k}" for k, v in zip(("mission", "fence", "rally"), lists.values(), strict=False)
    )
    out.print(f"stored {counts} items from {plan}")


@mission_app.command("save")
def mission_save(
    plan: Annotated[Path, typer.Argument(help=".plan file to write")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Write the vehicle's stored mission and rally points as a .plan file."""
    from companion.mission.plan import save_plan

    store = _mission_store(config)
    save_plan(plan, store.items)
    out.print(f"{len(store.items[0])} mission items written to {plan}")


@app.command()
def campaign(
    spec_file: Annotated[Path, typer.Argument(metavar="SPEC.toml", help="the campaign spec")],
    results: Annotated[
        Path | None, typer.Option("--out", help="results dir (default SPEC_results/)")
    ] = None,
    address: Annotated[str | None, typer.Option(help="Ray cluster (default: a local one)")] = None,
    cpus: Annotated[int | None, typer.Option(help="CPUs of the local Ray instance")] = None,
    retry_failed: Annotated[bool, typer.Option(help="fly failed flights again")] = False,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "WARNING",
) -> None:
    """Fly every flight of a campaign in lockstep simulation on Ray; score, tabulate, report."""
    from companion.campaign.runner import run_campaign
    from companion.campaign.spec import load_spec
    from companion.exec_control.config import ConfigError

    _setup_logging(log_level, "campaign")
    try:
        spec = load_spec(spec_file)
    except ConfigError as exc:
        err.print(f"[red]campaign spec error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    out_dir = results or Path(f"{spec_file.stem}_results")
    outcome = run_campaign(spec, out_dir, address, cpus, retry_failed, console=err)
    out.print(
        f"{outcome.flown} flown ({outcome.failed} failed), {outcome.skipped} already done; "
        f"results {outcome.results}" + (f", report {outcome.report}" if outcome.report else "")
    )
    raise typer.Exit(1 if outcome.failed else 0)


def main() -> None:
    """Console-script entry point."""
    app()


if __name__ == "__main__":
    main()
