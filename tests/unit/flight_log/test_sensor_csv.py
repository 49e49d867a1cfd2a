"""`companion log`: an on-board ULog becomes the sensor log CSV replay reads, values intact."""

from __future__ import annotations

import math
import random
import subprocess
import sys
from pathlib import Path

from companion.flight_log import ULogWriter, topic_name
from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer
from companion.navigation.sample_order import FEED_ORDER
from companion.sensors.sensorlog import LogStats, read_sensor_log
from tests.support.vehicle import REPO

KINDS = {
    "sensors/imu": Imu,
    "sensors/gps": GpsFix,
    "sensors/mag": Magnetometer,
    "sensors/baro": Baro,
    "sensors/compass": Compass,
}


def _samples(rng: random.Random) -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = []
    for i in range(200):
        t = 10_000 * i
        out.append(("sensors/imu", Imu(t, *(rng.uniform(-20, 20) for _ in range(6)), 25.0)))
        if i % 2 == 0:
            out.append(("sensors/mag", Magnetometer(t, *(rng.uniform(-1, 1) for _ in range(3)))))
            out.append(("sensors/baro", Baro(t, rng.uniform(0, 500), math.nan)))
            out.append(("sensors/compass", Compass(t, rng.uniform(0, 6.28), 0.1, -0.2, 20.0)))
        if i % 20 == 0:
            fix = GpsFix(t_us=t, lat_deg=-37.9 + rng.uniform(-0.01, 0.01), lon_deg=145.1)
            fix.alt_msl_m, fix.vn_m_s, fix.ve_m_s, fix.vd_m_s = 100.0, 20.0, 3.0, -1.0
            fix.hdop, fix.fix_type, fix.vd_std_m_s = 0.9, 3, 1.5
            if i % 60 == 40:  # a receiver without a fix, as a driver publishes it
                fix.lat_deg = fix.lon_deg = fix.alt_msl_m = fix.hdop = math.nan
                fix.fix_type, fix.vd_std_m_s = 1, math.nan
            out.append(("sensors/gps", fix))
    return out


def test_a_flight_log_converts_to_the_sensor_log_replay_reads(tmp_path: Path) -> None:
    samples = _samples(random.Random(7))
    ulg = tmp_path / "flight.ulg"
    with ulg.open("wb") as handle:
        writer = ULogWriter(handle, 0, [(topic_name(n), k) for n, k in KINDS.items()])
        for name, msg in samples:
            writer.data(topic_name(name), msg)
    csv_path = tmp_path / "flight.csv"
    done = subprocess.run(
        [sys.executable, "-m", "companion", "log", str(ulg), "--out", str(csv_path)],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert f"{len(samples)} sensor rows" in done.stdout
    assert "replay it with" not in done.stdout  # no navigator settings in this log's INFO
    stats = LogStats()
    back = list(read_sensor_log(csv_path, stats))
    assert stats.bad == 0  # no-fix samples included
    assert [m.t_us for m in back] == sorted(m.t_us for _, m in samples)  # in time order
    # At equal times in the order nav.ins_ekf feeds them (and a replay of the ULog does).
    rank = {KINDS[c]: i for i, c in enumerate(FEED_ORDER)}
    assert [(m.t_us, rank[type(m)]) for m in back] == sorted((m.t_us, rank[type(m)]) for m in back)
    # Within a time stamp the kinds come in a fixed order, so compare kind by kind.
    back.sort(key=lambda m: (type(m).__name__, m.t_us))
    samples.sort(key=lambda s: (type(s[1]).__name__, s[1].t_us))  # type: ignore[attr-defined]
    for (_, want), got in zip(samples, back, strict=True):
        assert type(got) is type(want) and got.t_us == want.t_us  # type: ignore[attr-defined]
        if isinstance(want, Imu):
            keys = ("ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s")
            assert [getattr(got, k) for k in keys] == [getattr(want, k) for k in keys]
        elif isinstance(want, GpsFix):
            keys = ("lat_deg", "lon_deg", "alt_msl_m", "vn_m_s", "ve_m_s", "vd_m_s", "hdop",
                    "vd_std_m_s", "fix_type")  # fmt: skip
            assert str([getattr(got, k) for k in keys]) == str([getattr(want, k) for k in keys])
        elif isinstance(want, Compass):
            assert math.isclose(got.heading_rad, want.heading_rad, abs_tol=1e-12)
            assert math.isclose(got.pitch_rad, 0.1) and math.isclose(got.roll_rad, -0.2)
        elif isinstance(want, Baro):
            assert got.alt_rel_m == want.alt_rel_m
        else:
            assert got.as_dict() == want.as_dict()


def test_a_missing_flight_log_is_a_clear_error(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "companion", "log", str(tmp_path / "no.ulg"), "-o", "x.csv"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode != 0 and "no such log" in done.stderr
