"""Reading the design's sensor log: every kind, absent columns, bad rows counted by line."""

from __future__ import annotations

import math

import pytest

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer
from companion.sensors.sensorlog import LogStats, read_sensor_log

HEADER = (
    "t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m,"
    "heading_deg,pitch_deg,roll_deg"
)


def write(tmp_path, *rows, header=HEADER):
    path = tmp_path / "log.csv"
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


def test_every_kind_becomes_its_message_with_the_log_time(tmp_path):
    path = write(
        tmp_path,
        "0.010,imu,0.1,-0.2,-9.81,0.01,0.02,-0.03,,,,,,,,,,,,,,,",
        "0.200,gps,,,,,,,-37.9105,145.134,120.5,10,0,,3,0.9,,,,,,,",
        "0.250,mag,,,,,,,,,,,,,,,0.21,0.05,-0.48,,,,",
        "0.300,baro,,,,,,,,,,,,,,,,,,3.2,,,",
        "0.350,compass,,,,,,,,,,,,,,,,,,,90.0,2.5,-1.0",
    )
    stats = LogStats()
    imu, gps, mag, baro, compass = read_sensor_log(path, stats)
    assert isinstance(imu, Imu) and imu.t_us == 10_000 and imu.az_m_s2 == -9.81
    assert isinstance(gps, GpsFix) and gps.lat_deg == -37.9105 and gps.fix_type == 3
    assert math.isnan(gps.vd_m_s) and gps.course_rad == 0.0 and gps.ground_speed_m_s == 10
    assert isinstance(mag, Magnetometer) and mag.mz_gauss == -0.48
    assert isinstance(baro, Baro) and baro.alt_rel_m == 3.2
    assert isinstance(compass, Compass) and compass.heading_rad == pytest.approx(math.pi / 2)
    assert stats.rows == 5 and stats.bad == 0


def test_older_files_without_the_compass_columns(tmp_path):
    old = HEADER.split(",heading_deg")[0]
    path = write(tmp_path, "1.0,baro,,,,,,,,,,,,,,,,,,7.5", header=old)
    (baro,) = read_sensor_log(path)
    assert baro.alt_rel_m == 7.5


def test_bad_rows_are_counted_named_and_skipped(tmp_path, caplog):
    path = write(
        tmp_path,
        "0.01,imu,0.1,0.2,-9.8,0,0,0,,,,,,,,,,,,,,,",
        "x,imu,0.1,0.2,-9.8,0,0,0,,,,,,,,,,,,,,,",
        "0.02,sonar,,,,,,,,,,,,,,,,,,,,,",
        "0.03,gps,,,,,,,95.0,145.1,10,0,0,,3,1,,,,,,,",
        "0.04,imu,0.1,0.2",
        "0.05,imu,0.1,0.2,-9.8,0,0,0,,,,,,,,,,,,,,,",
    )
    stats = LogStats()
    good = list(read_sensor_log(path, stats))
    assert [m.t_us for m in good] == [10_000, 50_000]
    assert stats.bad == 4 and stats.rows == 6
    assert "log.csv:4: skipped: unknown kind 'sonar'" in caplog.text
    assert "log.csv:5: skipped: gps row needs lat" in caplog.text


def test_a_file_that_is_not_a_log_is_refused(tmp_path):
    path = write(tmp_path, "1,2", header="a,b")
    with pytest.raises(ValueError, match="not a sensor log"):
        list(read_sensor_log(path))


def test_a_gps_sample_without_a_fix_is_read_as_one(tmp_path, caplog):
    # What `companion log` writes of a receiver without a fix (a driver publishes its
    # samples with fix 0/1 and no position): read, not refused; the navigators skip it.
    path = write(
        tmp_path,
        "149.94,gps,,,,,,,,,,,,,1,,,,,,,,",
        "149.96,gps,,,,,,,,,,,,,0,,,,,,,,",
        "150.00,gps,,,,,,,-37.9105,145.134,120.5,10,0,,1,0.9,,,,,,,",
    )
    stats = LogStats()
    fixes = list(read_sensor_log(path, stats))
    assert stats.bad == 0 and "skipped" not in caplog.text
    assert [f.fix_type for f in fixes] == [1, 0, 1]
    assert math.isnan(fixes[0].lat_deg) and math.isnan(fixes[1].lon_deg)
    assert fixes[2].lat_deg == -37.9105


def test_a_fix_without_a_possible_position_is_still_refused(tmp_path, caplog):
    path = write(
        tmp_path,
        "1.0,gps,,,,,,,,,,,,,3,0.9,,,,,,,",  # a 3-D fix with no position
        "1.2,gps,,,,,,,-37.9,,120,,,,2,,,,,,,,",  # 2-D, no longitude
        "1.4,gps,,,,,,,95.0,145.1,10,0,0,,3,1,,,,,,,",  # impossible latitude
        "1.6,gps,,,,,,,-37.9,181.0,10,0,0,,1,1,,,,,,,",  # no fix says it, the value is wrong
        "1.8,gps,,,,,,,,,,,,,,,,,,,,,",  # no fix column: a fix, as older logs meant
        "2.0,gps,,,,,,,nan,145.1,10,0,0,,3,1,,,,,,,",
    )
    stats = LogStats()
    assert list(read_sensor_log(path, stats)) == []
    assert stats.bad == 6 and stats.rows == 6
    assert caplog.text.count("skipped: gps row needs lat") == 6
