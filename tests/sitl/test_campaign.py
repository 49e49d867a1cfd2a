"""``companion campaign``: a handful of lockstep flights on a local Ray instance.

Two flights fly qgc_plans/short_leg.plan (calm, and a 4 m/s crosswind); two more use a
vehicle config without its MAVLink link, so the ground station never hears them: they
hang, and must be recorded as failed with their logs while the campaign finishes. A
rerun flies nothing. A flight whose vehicle cannot start is failed with the reason.
"""

from __future__ import annotations

import csv
import math
import re
import subprocess
import sys
from pathlib import Path

import psutil
import pytest
from pyulog import ULog

from ground.campaign.flight_run import FlightJob, fly_flight
from ground.campaign.spec import Flight
from tests.support.configs import vehicle_config
from tests.support.vehicle import REPO, companion_env

CAMPAIGN_FILE = re.compile(r"cmp_(camp\d+)p")  # a flight namespace's files, by campaign
SPEC = """
[campaign]
name = "small"
flight_timeout_s = 300
silent_s = 25

[flights]
plans = ["short_leg.plan"]
airframes = ["c172p"]
winds = [[0, 0, 0], [0, 4, 0]]
seeds = [3]
configs = ["", "silent.toml"]
"""


def silent_config(path: Path) -> None:
    """The shipped simulation config less its link plug-in: a vehicle nobody hears."""
    text = (REPO / "companion" / "configs" / "sim.toml").read_text()
    head, link, rest = text.partition('[[plugins]]\nname = "link"')
    assert link, "sim.toml has a link plug-in"
    path.write_text(head + rest[rest.index("[[plugins]]") :])


def campaign(spec: Path, out: Path) -> subprocess.CompletedProcess:
    args = [str(spec), "--out", str(out), "--cpus", "2"]
    return subprocess.run(
        [sys.executable, "-m", "companion", "campaign", *args],
        env=companion_env("campaign_driver"),
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=900,
    )


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "results.csv").open(newline="") as f:
        return list(csv.DictReader(f))


def campaign_files() -> dict[Path, str]:
    """Flight namespaces' files in /dev/shm, each with its campaign (``camp<worker pid>``,
    from the namespace ``camp<worker pid>p<port>``)."""
    found = {}
    for path in Path("/dev/shm").iterdir():
        if m := CAMPAIGN_FILE.match(path.name):
            found[path] = m.group(1)
    return found


def campaign_leftovers(others: set[str]) -> list[Path]:
    """Flight files in /dev/shm this campaign left: not of a campaign that was running
    before it, nor of a process still alive. A flight flown directly in another test's
    process (``fly_flight`` in the landing tests, on the other pytest worker) names its
    namespace after that living process; this campaign's Ray workers are gone once it
    returns."""
    return [
        path
        for path, owner in campaign_files().items()
        if owner not in others and not psutil.pid_exists(int(owner.removeprefix("camp")))
    ]


@pytest.mark.timeout(900)  # five lockstep flights on two cores: minutes on a busy machine
def test_a_small_campaign_scores_each_flight_and_survives_hung_ones(tmp_path):
    # Campaigns already running on the machine (a benchmark) are not this one's to judge.
    others = set(campaign_files().values())
    spec = tmp_path / "small.toml"
    spec.write_text(SPEC)
    silent_config(tmp_path / "silent.toml")
    out = tmp_path / "results"
    done = campaign(spec, out)
    assert done.returncode == 1, done.stdout + done.stderr  # two flights failed
    table = rows(out)
    assert len(table) == 4 and len({r["flight_id"] for r in table}) == 4
    flown = [r for r in table if r["config"] == "sim.toml"]
    hung = [r for r in table if r["config"] == "silent.toml"]
    assert {r["condition"] for r in flown} == {"calm none", "wind 0,4,0 none"}
    for row in flown:
        assert row["status"] == "ok" and row["completed"] == "True", row
        assert float(row["xtrack_rms_m"]) < 10.0 and float(row["xtrack_p95_m"]) < 15.0
        assert float(row["alt_rms_m"]) < 5.0 and int(row["samples"]) > 100
        assert 60.0 < float(row["time_to_complete_s"]) < float(row["sim_s"])
        assert row["failsafes"] == "", row  # nothing went wrong on these flights
        # The vehicle's own log of the flight is kept beside the results, whole.
        ulog = ULog(row["flight_log"])
        assert Path(row["flight_log"]).parent.name == row["flight_id"]
        # To the end of the flight (the vehicle time the ground station last saw).
        # The station hears the vehicle a little late on a busy machine (1.03 s in a CI run
        # with CPU hogs beside it); the log is whole to its end.
        assert ulog.last_timestamp / 1e6 == pytest.approx(float(row["sim_s"]), abs=2.0)
        assert len(ulog.get_dataset("nav_state").data["timestamp"]) > 1000
    for row in hung:
        assert row["status"] == "failed" and "hung" in row["error"], row
        assert math.isnan(float(row["xtrack_rms_m"]))
        assert Path(row["log"]).is_file()
    assert (out / "report.html").read_text().count("<tr>") == 5  # header and four flights
    assert (out / "distributions.png").stat().st_size > 0
    assert (out / "worst_tracks.png").stat().st_size > 0
    procs = psutil.process_iter(["cmdline"])
    left = [p for p in procs if str(out) in " ".join(p.info["cmdline"] or [])]
    assert not left, "a flight's processes outlived the campaign"
    assert not campaign_leftovers(others)

    # The same flight flown again outside Ray scores exactly the same (exact lockstep).
    calm = next(r for r in flown if r["condition"] == "calm none")
    sim_toml = str(REPO / "companion" / "configs" / "sim.toml")
    flight = Flight(str(REPO / "qgc_plans" / "short_leg.plan"), "c172p", (0.0, 0.0, 0.0), "none",
                    (), 3, sim_toml, False, 900.0, 10.0)  # fmt: skip
    alone = fly_flight(FlightJob(flight, str(tmp_path / "alone"), timeout_s=300.0))
    assert alone["flight_id"] == calm["flight_id"]
    # The same flight flown alone scores as it did inside the busy campaign, to the last digit.
    for key in ("xtrack_rms_m", "xtrack_p95_m", "alt_rms_m", "airspeed_rms_m_s", "samples"):
        assert float(alone[key]) == float(calm[key]), key
    # Completion is seen in the telemetry, which flows in wall time: to its resolution.
    assert abs(alone["time_to_complete_s"] - float(calm["time_to_complete_s"])) < 2.0

    again = campaign(spec, out)
    assert "0 flown (0 failed), 4 already done" in again.stdout
    assert rows(out) == table


def test_a_flight_whose_vehicle_cannot_start_is_failed_with_its_log(tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text(vehicle_config("sim", clokc="sim"))  # a typo: the vehicle refuses
    flight = Flight(str(REPO / "qgc_plans" / "short_leg.plan"), "c172p", (0.0, 0.0, 0.0), "none",
                    (), 1, str(broken), False, 600.0)  # fmt: skip
    row = fly_flight(FlightJob(flight, str(tmp_path / "flights"), timeout_s=120.0, silent_s=60.0))
    assert row["status"] == "failed" and "the simulation ended (exit 2)" in row["error"], row
    assert row["completed"] is False and math.isnan(row["xtrack_p95_m"])
    log = Path(row["log"]).read_text()
    assert "clokc" in log and "did you mean 'clock'" in log
