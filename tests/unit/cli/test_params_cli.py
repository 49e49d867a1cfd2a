"""`companion params` on a config's stored parameters: save/load, list/diff/set/reset."""

from __future__ import annotations

import subprocess
import sys

from tests.support.configs import FAKE_NAV, link, plugin, shipped_config, vehicle_config
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


def test_list_diff_set_and_reset_say_where_each_value_comes_from(tmp_path):
    airframe = tmp_path / "J3Cub.toml"
    shipped = (REPO / "companion" / "airframes" / "J3Cub.toml").read_text()
    airframe.write_text(shipped)
    control = plugin("control", "control.fixed_wing", group="flight")
    config = tmp_path / "v.toml"
    parts = (link("udpout://127.0.0.1:14999"), plugin("nav", FAKE_NAV), control)
    config.write_text(vehicle_config("p", *parts, state_dir=tmp_path / "s", airframe=airframe))
    assert companion("params", "diff", "-c", str(config)).stdout.strip() == (
        "every parameter at its default"
    )
    done = companion("params", "set", "WP_RADIUS", "45", "-c", str(config))
    assert done.returncode == 0 and "WP_RADIUS = 45 (stored)" in done.stdout
    airframe.write_text(shipped.replace("NAVL1_PERIOD = 14.0", "NAVL1_PERIOD = 17.0"))
    listed = rows(companion("params", "list", "-c", str(config)).stdout)
    assert listed["NAVL1_PERIOD"] == ["17", "airframe", "J3Cub.toml"]
    assert listed["WP_RADIUS"] == ["45", "stored", "(default", "30,", "default)"]
    assert listed["SR_GPS"] == ["2", "default"]
    assert listed["RTL_RETURN_ALT"][1:] == ["alias", "of", "RTL_ALT_M"]
    diff = companion("params", "diff", "-c", str(config)).stdout.splitlines()
    assert [line.split() for line in diff] == [["WP_RADIUS", "45", "default", "30", "(default)"]]
    refused = companion("params", "set", "WP_RADIUS", "0", "-c", str(config))
    assert refused.returncode == 2 and "WP_RADIUS: 0 outside" in refused.stderr
    assert companion("params", "reset", "-c", str(config)).returncode == 0
    assert rows(companion("params", "list", "-c", str(config)).stdout)["WP_RADIUS"] == [
        "30",
        "default",
    ]


def test_the_documented_round_trip_keeps_a_changed_return_altitude(tmp_path):
    # docs/parameters.md: save, reset, load. The file lists the PX4 names beside what they
    # follow (RTL_RETURN_ALT: RTL_ALT_M; RTL_DESCEND_ALT: RTL_LOITER_ALT_M).
    config, saved = str(shipped_config("hil", tmp_path)), tmp_path / "x.params"
    assert companion("params", "set", "RTL_RETURN_ALT", "120", "-c", config).returncode == 0
    assert companion("params", "set", "RTL_DESCEND_ALT", "60", "-c", config).returncode == 0
    assert companion("params", "save", str(saved), "-c", config).returncode == 0
    assert "RTL_RETURN_ALT\t120.0" in saved.read_text()
    assert "RTL_DESCEND_ALT\t60.0" in saved.read_text()
    assert companion("params", "reset", "-c", config).returncode == 0
    loaded = companion("params", "load", str(saved), "-c", config)
    assert loaded.returncode == 0, loaded.stderr
    listed = rows(companion("params", "list", "-c", config).stdout)
    assert listed["RTL_ALT_M"][:2] == ["120", "stored"]
    assert listed["RTL_LOITER_ALT_M"][:2] == ["60", "stored"]
    assert listed["RTL_RETURN_ALT"][0] == "120" and listed["RTL_DESCEND_ALT"][0] == "60"


def test_a_follower_contradicting_what_it_follows_is_refused_naming_both(tmp_path):
    config, saved = str(shipped_config("hil", tmp_path)), tmp_path / "x.params"
    companion("params", "set", "RTL_RETURN_ALT", "120", "-c", config)
    companion("params", "save", str(saved), "-c", config)
    companion("params", "reset", "-c", config)
    text = saved.read_text()
    for line, edited, said in (
        ("RTL_RETURN_ALT\t120.0", "RTL_RETURN_ALT\t90",
         "RTL_RETURN_ALT 90 contradicts RTL_ALT_M 120"),
        ("RTL_DESCEND_ALT\t100.0", "RTL_DESCEND_ALT\t50",
         "RTL_DESCEND_ALT 50 contradicts RTL_LOITER_ALT_M 100"),
    ):  # fmt: skip
        assert line in text
        saved.write_text(text.replace(line, edited))
        refused = companion("params", "load", str(saved), "-c", config)
        assert refused.returncode == 2 and said in refused.stderr, refused.stderr
        assert f"follows {said.split()[-2]}" in refused.stderr
    diff = companion("params", "diff", "-c", config).stdout.strip()
    assert diff == "every parameter at its default", "nothing applied from a refused file"


def rows(listing: str) -> dict[str, list[str]]:
    return {line.split()[0]: line.split()[1:] for line in listing.splitlines()}
