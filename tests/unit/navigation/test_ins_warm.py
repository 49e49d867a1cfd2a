"""Warm start: a navigator killed in the air and started again carries on from its last
solution instead of aligning cold (a jump of degrees and metres, half a second later)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.messages import Compass, GpsFix, Message, NavState
from companion.navigation.ins_warm import WarmFile, WarmState, warm_state
from companion.navigation.offline import InsEkfRunner, true_headings
from ground.simulation.evaluation import messages
from tests.unit.navigation.flights import DECLINATION, flight

KILL_S, GAP_S = 40.0, 1.5  # killed in the 8°/s turn; the new process reads on 1.5 s later


def _samples() -> list[Message]:
    return list(true_headings(messages(flight()), DECLINATION))


def _run_until(runner: InsEkfRunner, samples: list[Message], t0: float, t1: float) -> None:
    for s in samples:
        if t0 * 1e6 <= s.t_us < t1 * 1e6:
            runner.feed(s)


def _first_solution(runner: InsEkfRunner, samples: list[Message]) -> NavState:
    for s in samples:
        if s.t_us >= (KILL_S + GAP_S) * 1e6:
            runner.feed(s)
            if runner.nav.aligned:
                return runner.nav.state()
    raise AssertionError("never aligned")


def _errors(state: NavState) -> tuple[float, float, float, float]:
    """Roll, pitch, yaw (degrees) and horizontal position (m) off the truth."""
    truth = min(flight().truth, key=lambda s: abs(s.t_s - state.t_us / 1e6))
    att = [math.degrees(abs(math.remainder(a - b, math.tau)))
           for a, b in ((state.roll_rad, truth.roll), (state.pitch_rad, truth.pitch),
                        (state.yaw_rad, truth.yaw))]  # fmt: skip
    north = math.radians(state.lat_deg - truth.lat_deg) * 6_371_000
    east = (
        math.radians(state.lon_deg - truth.lon_deg)
        * 6_371_000
        * math.cos(math.radians(truth.lat_deg))
    )
    return (*att, math.hypot(north, east))


def _killed_in_the_turn() -> WarmState:
    before = InsEkfRunner(DECLINATION)
    _run_until(before, _samples(), 0.0, KILL_S)
    warm = warm_state(before.nav.state(), before.nav.lag.lag_s)
    assert warm is not None
    return warm


def test_a_restart_in_a_turn_starts_at_once_where_the_aircraft_is(tmp_path):
    file = WarmFile(tmp_path)
    file.write(_killed_in_the_turn())
    warm, cold = InsEkfRunner(DECLINATION), InsEkfRunner(DECLINATION)
    warm.nav.warm = file.read()
    samples = _samples()
    w, c = _first_solution(warm, samples), _first_solution(cold, samples)
    # At the first fix, not after the cold alignment's half second of IMU.
    assert w.t_us < c.t_us
    roll, pitch, yaw, pos = _errors(w)
    assert max(roll, pitch) < 1.0 and yaw < 2.0 and pos < 3.0, _errors(w)


def test_on_the_ground_or_long_after_the_file_the_alignment_is_cold(tmp_path):
    warm = _killed_in_the_turn()
    nav = InsEkfRunner(DECLINATION).nav
    standing = GpsFix(t_us=warm.t_us + 1_000_000, lat_deg=warm.lat_deg, lon_deg=warm.lon_deg,
                      alt_msl_m=warm.alt_msl_m, fix_type=3)  # fmt: skip
    stale = GpsFix(t_us=warm.t_us + 60_000_000, lat_deg=warm.lat_deg, lon_deg=warm.lon_deg,
                   alt_msl_m=warm.alt_msl_m, vn_m_s=25.0, fix_type=3)  # fmt: skip
    for fix in (standing, stale):
        nav.warm = warm
        nav.on_gps(fix)
        nav.on_compass(Compass(t_us=fix.t_us, heading_rad=0.0))
        nav.on_imu(_level_imu(fix.t_us + 1000))
        assert not nav.aligned  # a cold alignment collects its window first
    assert WarmFile(tmp_path).read() is None  # no file: cold
    (tmp_path / "nav_warm.json").write_text('{"t_us": 1')  # cut short: cold
    assert WarmFile(tmp_path).read() is None


def test_nothing_is_written_on_the_ground():
    state = NavState(t_us=1, flags=1, lat_deg=45.0, lon_deg=7.0, alt_msl_m=300.0, vn_m_s=1.0)
    assert warm_state(state, 0.2) is None
    state.vn_m_s = 25.0
    assert warm_state(state, 0.2) is not None


def _level_imu(t_us: int) -> Message:
    from companion.messages import Imu

    return Imu(t_us=t_us, az_m_s2=-9.81, temp_c=np.nan)


@pytest.mark.parametrize(("kill_s", "back_s"), [(48.0, 54.0), (66.0, 74.0)])
def test_after_a_long_gap_the_attitude_is_the_one_of_now_not_the_files_turned_on(
    tmp_path, kill_s, back_s
):
    # The whole vehicle restarted (6-8 s): killed banked in the 8°/s turn and started again
    # wings level in the climb after it; or killed in the climb and started in the -6°/s
    # turn. Nobody saw the aircraft roll meanwhile: the file's attitude turned by the
    # gyros' rate of now over the whole gap was 12° off in roll and 24-29° in heading.
    before = InsEkfRunner(DECLINATION)
    samples = _samples()
    _run_until(before, samples, 0.0, kill_s)
    file = WarmFile(tmp_path)
    file.write(warm_state(before.nav.state(), before.nav.lag.lag_s))  # type: ignore[arg-type]
    warm = InsEkfRunner(DECLINATION)
    warm.nav.warm = file.read()
    first = None
    for s in samples:
        if s.t_us >= back_s * 1e6:
            warm.feed(s)
            if warm.nav.aligned:
                first = warm.nav.state()
                break
    assert first is not None
    roll, pitch, yaw, pos = _errors(first)
    assert max(roll, pitch) < 5.0 and yaw < 10.0 and pos < 25.0, _errors(first)
    # A warm start: the biases carried over, not learnt again from the defaults.
    assert np.allclose(warm.nav.bg, before.nav.bg, atol=1e-6)


def _level_imu(t_us: int) -> Message:
    from companion.messages import Imu

    return Imu(t_us=t_us, az_m_s2=-9.81, temp_c=np.nan)


def test_a_new_state_directory_is_made_and_a_failing_disk_is_said_once(tmp_path, caplog):
    state = _killed_in_the_turn()
    fresh = WarmFile(tmp_path / "new" / "state")  # --state-dir naming one not made yet
    fresh.write(state)
    assert fresh.read() is not None and fresh.failures == 0
    fresh.close()
    (tmp_path / "file").write_text("")
    broken = WarmFile(tmp_path / "file" / "state")  # its parent is a file: never writable
    with caplog.at_level("DEBUG", logger="companion.navigation.ins_warm"):
        for i in range(10):
            broken.write(WarmState(**{**vars(state), "t_us": state.t_us + i * 200_000}))
    warnings = [r for r in caplog.records if r.levelname == "WARNING"]
    assert broken.failures == 10 and len(warnings) == 1
