"""The log recorder: a log grows past neither its file size nor the directory's budget, and a
cut at the wrong moment never leaves a headless ``.ulg`` in view."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest
from pyulog import ULog

from companion.flight_log import LogDirectory, LogRecorder, topic_name
from companion.messages import Imu

TOPICS = [(topic_name("sensors/imu"), Imu)]
INFO = {"sys_name": "companion", "vehicle_name": "test"}


def recorder(tmp_path: Path, budget: int, max_bytes: int) -> LogRecorder:
    params = {"SYSID": 3}
    return LogRecorder(LogDirectory(tmp_path / "logs", budget), TOPICS, INFO, params, max_bytes)


def write(rec: LogRecorder, first: int, count: int) -> None:
    assert rec.writer is not None
    for i in range(first, first + count):
        rec.writer.data("sensors_imu", Imu(t_us=1_000 * i, ax_m_s2=float(i)))


def ax(path: Path) -> list[float]:
    ulog = ULog(str(path))
    if not ulog.data_list:  # a file begun at the last flush, closed before any sample
        return []
    return [float(x) for x in ulog.get_dataset("sensors_imu").data["ax_m_s2"]]


def test_a_full_file_goes_on_in_a_new_one_at_a_flush(tmp_path: Path) -> None:
    rec = recorder(tmp_path, budget=10**9, max_bytes=20_000)
    rec.open("armed", 0)
    for second in range(6):  # 6 x 250 samples of ~50 bytes: 75 kB in files of 20-40 kB
        write(rec, second * 250, 250)
        rec.flush(second * 1_000_000)
    rec.close()
    files = rec.logs.files()
    assert len(files) >= 3
    assert all(p.name.endswith("_armed.ulg") for p in files)
    # Each file is whole and readable on its own; together they hold every sample in order.
    assert all(20_000 <= p.stat().st_size < 2 * 20_000 for p in files[:-1])
    assert [x for p in files for x in ax(p)] == [float(i) for i in range(1_500)]
    assert ULog(str(files[-1])).initial_parameters["SYSID"] == 3


def test_the_budget_is_kept_while_a_file_is_written(tmp_path: Path) -> None:
    logs = LogDirectory(tmp_path / "logs", 0)
    old = logs.new_path("armed")
    old.write_bytes(bytes(30_000))
    rec = recorder(tmp_path, budget=40_000, max_bytes=10**9)
    rec.open("boot", 0)
    assert old.exists()  # the new log is small yet: within the budget
    write(rec, 0, 200)
    rec.flush(1_000_000)  # not closed: pruned all the same
    assert not old.exists()
    assert rec.logs.files() == [rec.path]


def test_a_cut_before_the_header_is_on_disk_leaves_no_log_in_view(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_fsync = os.fsync

    def power_cut(fd: int) -> None:  # at the header's fsync (a directory's goes through)
        if stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError("power cut")
        real_fsync(fd)

    rec = recorder(tmp_path, budget=10**9, max_bytes=10**9)
    with monkeypatch.context() as patch:
        patch.setattr(os, "fsync", power_cut)
        with pytest.raises(OSError, match="power cut"):
            rec.open("armed", 0)
    rec.abandon()  # the process is gone: its lock with it
    assert rec.logs.files() == []  # nothing a ground station would list
    assert [p.name for p in (tmp_path / "logs").iterdir()] == [".0001_armed.ulg.part"]
    # The next start clears the remains and numbers on as if there had been none.
    rec = recorder(tmp_path, budget=10**9, max_bytes=10**9)
    assert rec.open("armed", 0).name == "0001_armed.ulg"
    assert [p.name for p in (tmp_path / "logs").iterdir()] == ["0001_armed.ulg"]
    assert rec.path is not None and rec.path.stat().st_size > 0  # the header is there
    rec.close()
    assert ULog(str(rec.path)).msg_info_dict["vehicle_name"] == "test"  # pyulog reads it
