"""`companion params save/load` on a config's stored parameters."""

from __future__ import annotations

import subprocess
import sys

from tests.support.configs import link, vehicle_config
from tests.support.vehicle import REPO


def companion(*args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "companion", *args]
    return subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=60)


def test_save_edit_load_round_trip_and_a_bad_file_is_refused(tmp_path):
    config = tmp_path / "v.toml"
    config.write_text(
        vehicle_config("p", link("udpout://127.0.0.1:14999"), state_dir=tmp_path / "state")
    )
    saved = tmp_path / "v.params"
    assert companion("params", "save", str(saved), "-c", str(config)).returncode == 0
    text = saved.read_text()
    assert "1\t1\tSR_GPS\t2.0\t9" in text
    saved.write_text(text.replace("SR_GPS\t2.0", "SR_GPS\t5.0"))
    assert companion("params", "load", str(saved), "-c", str(config)).returncode == 0
    again = tmp_path / "again.params"
    companion("params", "save", str(again), "-c", str(config))
    assert "SR_GPS\t5.0" in again.read_text()
    saved.write_text("1\t1\tSR_GPS\t500\t9\n")
    bad = companion("params", "load", str(saved), "-c", str(config))
    assert bad.returncode == 2 and "v.params:1: SR_GPS: 500 outside" in bad.stderr
