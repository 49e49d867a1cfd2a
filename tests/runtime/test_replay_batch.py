"""``companion replay`` over many logs on Ray: an estimate each, a summary, failures kept.

The logs are short synthetic flights (35 s); most of each run is Ray starting and
stopping. Each run is its own session, so that whatever Ray left behind can be found.
"""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ground.replay.batch import LogsError, find_logs, is_batch
from ground.simulation.synthetic_flight import FlightSpec, Leg
from ground.simulation.synthetic_log import synthesize
from tests.support.vehicle import REPO

LEGS = (Leg(15), Leg(10, turn_deg_s=8), Leg(10))
OUTAGE = (12.0, 8.0)  # start, seconds without GPS, in flight2
GPS_PERIOD_S = 1 / FlightSpec().gps_hz
FLIGHTS = {"flight1": None, "flight2": OUTAGE, "flight3": None}


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("logs")
    for seed, (name, outage) in enumerate(FLIGHTS.items(), start=1):
        synthesize(FlightSpec(legs=LEGS, seed=seed, outage=outage)).write(folder / f"{name}.csv")
    (folder / "corrupt.csv").write_text("garbage,here\n1,2\n")
    return folder


def _companion(*args: str) -> subprocess.CompletedProcess:
    """The command in a session of its own; fails the test if Ray left anything behind."""
    shm_before = set(os.listdir("/dev/shm"))
    proc = subprocess.Popen(
        [sys.executable, "-m", "companion", *args], cwd=REPO, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, start_new_session=True,
    )  # fmt: skip
    try:
        stdout, stderr = proc.communicate(timeout=150)
    finally:
        left = _wait_session_gone(proc.pid)
        if left:
            os.killpg(proc.pid, signal.SIGKILL)
    assert not left, f"processes left running: {left}"
    # Replay uses no bus: files of the bus (cmp_*) are other tests' vehicles, running meanwhile.
    new = {n for n in set(os.listdir("/dev/shm")) - shm_before if not n.startswith("cmp_")}
    assert not new, f"left in /dev/shm: {sorted(new)}"
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)


def _wait_session_gone(sid: int, timeout_s: float = 15.0) -> list[int]:
    deadline = time.monotonic() + timeout_s
    while (members := _session_members(sid)) and time.monotonic() < deadline:
        time.sleep(0.2)
    return members


def _session_members(sid: int) -> list[int]:
    members = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue  # gone meanwhile
        if int(fields[3]) == sid:
            members.append(int(stat.parent.name))
    return members


def _summary(path: Path) -> dict[str, dict[str, str]]:
    with path.open(newline="") as handle:
        return {Path(r["log"]).stem: r for r in csv.DictReader(handle)}


@pytest.mark.timeout(240)
def test_a_folder_of_logs_with_a_corrupt_one(logs, tmp_path):
    out = tmp_path / "out"
    result = _companion("replay", str(logs), "--out", str(out), "--navigator", "ins_ekf",
                        "--cpus", "2")  # fmt: skip
    assert result.returncode == 1, result.stderr  # the corrupt log
    assert sorted(p.name for p in out.iterdir()) == [
        "flight1.estimate.csv", "flight2.estimate.csv", "flight3.estimate.csv", "summary.csv",
    ]  # fmt: skip
    assert "3 ok, 1 failed" in result.stdout
    rows = _summary(out / "summary.csv")
    assert {name: r["status"] for name, r in rows.items()} == {
        "corrupt": "failed", "flight1": "ok", "flight2": "ok", "flight3": "ok",
    }  # fmt: skip
    assert "not a sensor log" in rows["corrupt"]["error"]
    for name in FLIGHTS:
        row = rows[name]
        assert row["error"] == "" and int(row["bad_rows"]) == 0
        assert float(row["duration_s"]) == pytest.approx(35.0, abs=0.1)
        assert int(row["estimates"]) > 30 * 50
        assert 0 < float(row["final_pos_std_m"]) < 5 and 0 < float(row["final_yaw_std_deg"]) < 5
    assert [rows[n]["gps_outages"] for n in FLIGHTS] == ["0", "1", "0"]
    outage = float(rows["flight2"]["gps_outage_total_s"])
    assert OUTAGE[1] <= outage <= OUTAGE[1] + 1.5 * GPS_PERIOD_S
    assert float(rows["flight2"]["longest_gps_gap_s"]) == outage
    assert float(rows["flight1"]["longest_gps_gap_s"]) < 1.5 * GPS_PERIOD_S

    # The batch's estimate is the single replay's, byte for byte.
    single = tmp_path / "single.csv"
    one = subprocess.run(
        [sys.executable, "-m", "companion", "replay", str(logs / "flight2.csv"), "--out",
         str(single), "--navigator", "ins_ekf"],
        cwd=REPO, capture_output=True, text=True, timeout=100,
    )  # fmt: skip
    assert one.returncode == 0, one.stderr
    assert single.read_bytes() == (out / "flight2.estimate.csv").read_bytes()


@pytest.mark.timeout(240)
def test_a_quoted_pattern(logs, tmp_path):
    out = tmp_path / "out"
    result = _companion("replay", str(logs / "flight[13].csv"), "--out", str(out),
                        "--navigator", "gps_compass", "--cpus", "2")  # fmt: skip
    assert result.returncode == 0, result.stderr
    rows = _summary(out / "summary.csv")
    assert {name: r["status"] for name, r in rows.items()} == {"flight1": "ok", "flight3": "ok"}
    assert rows["flight1"]["final_yaw_std_deg"] == ""  # gps_compass does not estimate it


def test_what_names_a_batch(logs, tmp_path):
    assert not is_batch([str(logs / "flight1.csv")])
    assert is_batch([str(logs)])
    assert is_batch([str(logs / "*.csv")])
    assert is_batch([str(logs / "flight1.csv"), str(logs / "flight2.csv")])
    # A folder holding logs and their estimates gives the logs only, each once.
    (logs / "flight1.estimate.csv").write_text("t\n")
    try:
        found = find_logs([str(logs), str(logs / "flight*.csv")], logs)
    finally:
        (logs / "flight1.estimate.csv").unlink()
    assert [p.name for p in found] == ["corrupt.csv", "flight1.csv", "flight2.csv", "flight3.csv"]
    with pytest.raises(LogsError, match="no file matches"):
        find_logs([str(logs / "nope*.csv")], tmp_path)
    other = tmp_path / "flight1.csv"
    other.write_text("t\n")
    with pytest.raises(LogsError, match=r"would both write flight1\.estimate\.csv"):
        find_logs([str(logs / "flight1.csv"), str(other)], tmp_path)
