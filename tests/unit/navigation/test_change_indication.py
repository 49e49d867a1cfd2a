"""Change indication (PX4 ekf2's habit): nav.ins_ekf's estimate over two real flight logs is
committed at reduced precision beside this file, and regenerated and compared here. Any
change of the navigator's behaviour shows as a failing test and, once accepted, as a
reviewable diff of ``golden/*.csv``.

To accept a change, run this file with ``NAV_GOLDEN_UPDATE=1`` in the environment,
then review ``git diff tests/unit/navigation/golden`` and commit it with the change.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path

import pytest

from companion.messages import NavFlags
from companion.navigation.local_frame import LocalFrame
from companion.navigation.offline import InsEkfRunner, run_navigator
from companion.sensors.sensorlog import read_sensor_log

NAVLOGS = Path(__file__).resolve().parents[4] / "shared" / "navlogs" / "data"
GOLDEN = Path(__file__).with_name("golden")
LOGS = ("plane_alfa_1005_nofail", "copter_ac344_0036")  # a fixed-wing and a multicopter
COLUMNS = ("t", "roll_deg", "pitch_deg", "yaw_deg", "north_m", "east_m", "alt_m",
           "vn_m_s", "ve_m_s", "vd_m_s")  # fmt: skip
# One decimal: coarse enough that floating-point differences between machines do not
# show, fine enough that a change of behaviour does (a tenth of a degree, a decimetre).
DECIMALS = 1
TOLERANCE = 1.5 * 10**-DECIMALS  # a rounding flip of the last digit is not a change


def estimate_rows(name: str) -> list[list[str]]:
    """The navigator's estimate over the log, once a second, rounded."""
    runner = InsEkfRunner()
    rows: list[list[str]] = []
    frame: LocalFrame | None = None
    samples = read_sensor_log(NAVLOGS / f"{name}.sensors.csv")
    for s in run_navigator(runner, samples, rate_hz=1.0):
        if not s.flags & NavFlags.POSITION_VALID:
            continue
        if frame is None:
            frame = LocalFrame(s.lat_deg, s.lon_deg, 0.0)
        north, east, _ = frame.ned(s.lat_deg, s.lon_deg, 0.0)
        values = (math.degrees(s.roll_rad), math.degrees(s.pitch_rad),
                  math.degrees(s.yaw_rad), north, east, s.alt_msl_m,
                  s.vn_m_s, s.ve_m_s, s.vd_m_s)  # fmt: skip
        cells = [f"{v:.{DECIMALS}f}" for v in values]
        rows.append(
            [f"{s.t_us / 1e6:.0f}"]
            + [c.replace("-0.0", "0.0") if c == "-0.0" else c for c in cells]
        )
    return rows


def differences(expected: list[list[str]], got: list[list[str]]) -> list[str]:
    """Human-readable differences beyond the tolerance (the first few)."""
    if len(expected) != len(got):
        return [f"{len(got)} rows, the golden file has {len(expected)}"]
    found = []
    for old, new in zip(expected, got, strict=True):
        for column, a, b in zip(COLUMNS, old, new, strict=True):
            delta = abs(float(a) - float(b))
            if column == "yaw_deg":
                delta = abs(math.remainder(delta, 360.0))
            if delta > TOLERANCE:
                found.append(f"t={new[0]} s {column}: {a} -> {b}")
    return found


@pytest.mark.parametrize("name", LOGS)
def test_the_estimate_over_a_real_log_is_unchanged(name: str):
    if not (NAVLOGS / f"{name}.sensors.csv").is_file():
        pytest.skip(f"the real-log set is not beside the project ({NAVLOGS})")
    got = estimate_rows(name)
    path = GOLDEN / f"{name}.csv"
    if os.environ.get("NAV_GOLDEN_UPDATE"):
        GOLDEN.mkdir(exist_ok=True)
        with path.open("w", newline="") as handle:
            csv.writer(handle, lineterminator="\n").writerows([list(COLUMNS), *got])
    with path.open() as handle:
        expected = list(csv.reader(handle))[1:]
    changed = differences(expected, got)
    assert not changed, (
        f"nav.ins_ekf's estimate over {name} changed ({len(changed)} values), e.g.\n"
        + "\n".join(changed[:10])
        + "\nIf intended: NAV_GOLDEN_UPDATE=1 uv run pytest "
        + Path(__file__).name
    )
