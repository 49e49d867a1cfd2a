"""The opt-in profile of a plug-in process: written only when asked, for whom it was asked."""

from __future__ import annotations

import os
import pstats
import threading
import time

from companion.exec_control.profiling import ENV_DIR, ENV_ONLY, profile_path, run_profiled


def _work() -> int:
    return sum(i * i for i in range(1000))


def test_without_the_variable_nothing_is_profiled(tmp_path, monkeypatch):
    monkeypatch.delenv(ENV_DIR, raising=False)
    assert profile_path("imu") is None
    assert run_profiled("imu", _work) == _work()
    assert not any(tmp_path.iterdir())


def test_a_profile_per_plugin_process_with_its_functions(tmp_path, monkeypatch):
    monkeypatch.setenv(ENV_DIR, str(tmp_path / "prof"))
    monkeypatch.setenv(ENV_ONLY, "imu, nav")
    assert run_profiled("imu", _work) == _work()
    assert run_profiled("gps", _work) == _work()  # not asked for
    written = sorted(p.name for p in (tmp_path / "prof").iterdir())
    assert written == [f"imu.{os.getpid()}.prof"]
    stats = pstats.Stats(str(tmp_path / "prof" / written[0]))
    assert any(name == "_work" for _, _, name in stats.stats)  # type: ignore[attr-defined]


def test_a_composed_thread_s_profile_counts_its_own_cpu_only(tmp_path, monkeypatch):
    """In a composed process each plug-in thread's profile is timed by that thread's CPU:
    a neighbour spinning meanwhile is not charged to a thread that sleeps."""
    monkeypatch.setenv(ENV_DIR, str(tmp_path / "prof"))
    monkeypatch.delenv(ENV_ONLY, raising=False)
    done = threading.Event()

    def spin() -> None:
        while not done.is_set():
            _work()

    def mostly_asleep() -> None:
        for _ in range(30):
            time.sleep(0.01)

    neighbour = threading.Thread(target=spin)
    neighbour.start()
    try:
        profiled = threading.Thread(target=run_profiled, args=("gps", mostly_asleep, True))
        profiled.start()
        profiled.join()
    finally:
        done.set()
        neighbour.join()
    stats = pstats.Stats(str(tmp_path / "prof" / f"gps.{os.getpid()}.prof"))
    assert stats.total_tt < 0.05  # type: ignore[attr-defined]  # the spinner: about 0.3 s
