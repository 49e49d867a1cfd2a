"""The documentation's figures, drawn from measurements (never by hand).

Usage: uv run python benchmarks/plots.py [tracking] [navigation] [--out docs/img]

- ``tracking``: one exact-lockstep campaign flight of ``qgc_plans/square.plan`` (c172p,
  calm; ground/campaign/flight_run.py, as ``mission_tracking.py`` flies it), drawn from
  the simulator's truth: the track over the plan's legs seen from above, and the height
  against the plan's. Its score is printed and written in the title.
- ``navigation``: ``plane_alfa_0730_nofail`` of the real flight logs (``../shared/navlogs``)
  replayed through the ``ins_ekf`` navigator (``companion replay``'s own code), its roll,
  pitch and heading against the autopilot's own estimate, with the errors below.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display on a build machine
import matplotlib.pyplot as plt
import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.control.mission.plan import checked_plan  # noqa: E402
from companion.geodesy import LocalFrame  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.flight_run import FlightJob, fly_flight  # noqa: E402
from ground.campaign.spec import PLANS, SIM_CONFIG, Flight  # noqa: E402
from ground.replay.single import replay_log  # noqa: E402

NAVLOGS = REPO.parent / "shared" / "navlogs"
REAL_LOG = "plane_alfa_0730_nofail"


def tracking(out: Path) -> Path:
    """Fly the square and draw it; the PNG's path."""
    plan = PLANS / "square.plan"
    flight = Flight(str(plan), "c172p", (0.0, 0.0, 0.0), "none", (), 1, str(SIM_CONFIG),
                    False, 900.0, 10.0)  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        row = fly_flight(FlightJob(flight, tmp, timeout_s=900.0))
        truth = read_estimate(Path(tmp) / flight.flight_id / "truth.csv")
    points = [(i.x / 1e7, i.y / 1e7) for i in checked_plan(plan)[0] if i.x != 0 or i.y != 0]
    frame = LocalFrame(float(truth["lat"][0]), float(truth["lon"][0]))
    track = np.array([frame.ne(la, lo) for la, lo in zip(truth["lat"], truth["lon"], strict=True)])
    legs = np.array([frame.ne(lat, lon) for lat, lon in points])
    fig, (top, side) = plt.subplots(1, 2, figsize=(11, 4.8), width_ratios=(1.2, 1))
    top.plot(legs[:, 1], legs[:, 0], "o--", color="grey", label="plan")
    top.plot(track[:, 1], track[:, 0], color="tab:blue", lw=1.2, label="flown (truth)")
    top.set(xlabel="east (m)", ylabel="north (m)", aspect="equal", title="seen from above")
    top.legend(loc="lower right")
    t = np.asarray(truth["t"])
    side.plot(t, np.asarray(truth["alt"]) - truth["alt"][0], color="tab:blue")
    side.set(xlabel="simulated time (s)", ylabel="height above the runway (m)", title="height")
    fig.suptitle(
        f"square.plan, c172p, calm, exact lockstep: cross-track RMS {row['xtrack_rms_m']:.2f} m,"
        f" p95 {row['xtrack_p95_m']:.2f} m, height RMS {row['alt_rms_m']:.2f} m"
    )
    print(f"tracking: {row['xtrack_rms_m']:.2f} m RMS, {row['xtrack_p95_m']:.2f} m p95")
    return _save(fig, out / "tracking_square_c172p.png")


def navigation(out: Path, navlogs: Path = NAVLOGS) -> Path | None:
    """Replay the real log and draw the attitude against the reference; the PNG's path."""
    sensors = navlogs / "data" / f"{REAL_LOG}.sensors.csv"
    if not sensors.exists():
        print(f"navigation: {sensors} not found: no figure")
        return None
    with tempfile.TemporaryDirectory() as tmp:
        estimate = Path(tmp) / "estimate.csv"
        replay_log(sensors, "ins_ekf", estimate)
        ours = read_estimate(estimate)
    ref = read_estimate(navlogs / "data" / f"{REAL_LOG}.reference.csv")
    t = np.asarray(ref["t"])
    fig, axes = plt.subplots(2, 3, figsize=(13, 6), sharex=True)
    for k, name in enumerate(("roll", "pitch", "yaw")):
        mine = np.interp(t, ours["t"], np.unwrap(ours[name]))
        theirs = np.unwrap(np.asarray(ref[name]))
        error = np.degrees((mine - theirs + math.pi) % (2 * math.pi) - math.pi)
        axes[0, k].plot(t, np.degrees(theirs), color="grey", label="autopilot's estimate")
        axes[0, k].plot(t, np.degrees(mine), color="tab:blue", lw=1, label="ins_ekf")
        axes[0, k].set(title=f"{name} (°)")
        axes[1, k].plot(t, error, color="tab:red", lw=1)
        rms = float(np.sqrt(np.mean(error[t > t[0] + 10.0] ** 2)))
        axes[1, k].set(xlabel="time (s)", title=f"{name} error (°), RMS {rms:.2f}")
    axes[0, 0].legend(loc="lower left")
    fig.suptitle(f"real flight log {REAL_LOG}: ins_ekf against the autopilot's own estimate")
    return _save(fig, out / f"navigation_{REAL_LOG}.png")


def _save(fig: plt.Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    print(f"wrote {path}")
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("figures", nargs="*", default=["tracking", "navigation"])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "img")
    args = parser.parse_args()
    for name in args.figures:
        {"tracking": tracking, "navigation": navigation}[name](args.out)


if __name__ == "__main__":
    main()
