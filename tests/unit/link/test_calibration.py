"""MAV_CMD_PREFLIGHT_CALIBRATION in process: PX4's answers and "[cal]" texts, what the gyro
and level calibrations measure from the IMU's samples, and that the IMU driver's correction
with the stored result gives what a level, still, unbiased IMU would."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pymavlink.dialects.v20 import common as m

from companion.link.calibration_service import WINDOW_S, Calibration
from companion.link.codec import new_encoder
from companion.link.command_service import CommandArgs, CommandService
from companion.link.commands.calibration import CalibrationCommands, requested
from companion.link.commands.storage import StorageCommands
from companion.link.microservice import Peer
from companion.link.params_service import ParamsService
from companion.messages import Imu, SystemHealth
from companion.params import ParamDecl, ParamError, ParamStore
from companion.params.live import RELOAD_ALL
from companion.sensors.imu_calibration import IMU_CAL_PARAMS, ImuCalibration, mounting, rotate
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)
G = 9.80665
CAL = m.MAV_CMD_PREFLIGHT_CALIBRATION
GYRO, LEVEL, ACCEL, CANCEL = (1, 0, 0, 0, 0), (0, 0, 0, 0, 2), (0, 0, 0, 0, 1), ()


def args(*params: float) -> CommandArgs:
    return CommandArgs(CAL, (*params, *[0.0] * (7 - len(params))), 0, GCS)


class Bench:
    """The calibration commands with the IMU driver's parameters, a vehicle port that
    records texts, and an IMU whose samples the test writes."""

    def __init__(self, **values: float) -> None:
        self.vehicle = RecordingVehicle()
        self.store = ParamStore(IMU_CAL_PARAMS)
        for name, value in values.items():
            self.store.set(name, value)
        self.params = ParamsService(new_encoder(1, 1), self.store, 1, 1)
        self.changed: list[tuple[str, float]] = []
        self.params.on_change = lambda name, value: self.changed.append((name, value))
        self.calibration = Calibration(self.vehicle, self.params)
        self.commands = CalibrationCommands(self.vehicle, self.calibration)
        self.storage = StorageCommands(self.vehicle, self.params, self.calibration)
        self.t_us = 10_000_000
        self.vehicle.snapshot.now_us = self.t_us
        self.vehicle.snapshot.imu = Imu(t_us=self.t_us)

    def command(self, *params: float) -> int:
        return self.commands.calibrate(args(*params)).result

    def run(self, raw, seconds: float, rate_hz: float = 100.0, rng=None) -> list:
        """``raw`` (accel, gyro) samples for ``seconds`` of IMU time, each corrected by the
        stored calibration as the IMU driver corrects them; the PARAM_VALUEs sent."""
        out = self.calibration.tick(0.0)
        for _ in range(round(seconds * 10)):
            feed = self.vehicle.feeds[-1] if self.vehicle.feeds else None
            for _ in range(round(rate_hz / 10)):
                self.t_us += round(1e6 / rate_hz)
                imu = sample(self.t_us, raw, rng)
                cal = ImuCalibration.from_params(self.store.values)
                cal.correct(imu, None, cal.rotation)
                if feed is not None:
                    feed.pending.append(imu)
            self.vehicle.snapshot.now_us, self.vehicle.snapshot.imu = self.t_us, imu
            out += self.calibration.tick(0.0)
        return out

    @property
    def cal_texts(self) -> list[str]:
        return [t.removeprefix("[cal] ") for t in self.vehicle.texts if t.startswith("[cal] ")]


def sample(t_us: int, raw, rng=None) -> Imu:
    accel, gyro = raw
    noise = rng.normal(0.0, [0.05] * 3 + [0.002] * 3) if rng is not None else np.zeros(6)
    a, w = np.add(accel, noise[:3]), np.add(gyro, noise[3:])
    return Imu(t_us=t_us, ax_m_s2=a[0], ay_m_s2=a[1], az_m_s2=a[2],
               gx_rad_s=w[0], gy_rad_s=w[1], gz_rad_s=w[2])  # fmt: skip


def mounted(roll_deg: float, pitch_deg: float, bias=(0.0, 0.0, 0.0)):
    """What a still IMU mounted rolled and pitched so on a level aircraft reads."""
    m_ = mounting(math.radians(roll_deg), math.radians(pitch_deg))
    back = tuple(tuple(m_[j][i] for j in range(3)) for i in range(3))
    return rotate(back, 0.0, 0.0, -G), bias


@pytest.mark.parametrize(("params", "kind"), [
    ((1,), "gyro"), ((0, 1), "mag"), ((0, 0, 1), "baro"), ((0, 0, 0, 1), "radio"),
    ((0, 0, 0, 2), "trims"), ((0, 0, 0, 0, 1), "accel"), ((0, 0, 0, 0, 2), "level"),
    ((0, 0, 0, 0, 4), "accel"), ((0, 0, 0, 0, 0, 1), "airspeed"), ((0, 0, 0, 0, 0, 2), "airspeed"),
    ((0, 0, 0, 0, 0, 0, 1), "esc"), ((3,), "temperature"), ((0, 0, 0, 0, 3), "temperature"),
    ((1, 1), "gyro"), ((), "cancel"), ((2,), None), ((0, 0, 0, 0, 3, 0, 2), "temperature"),
])  # fmt: skip
def test_the_calibration_asked_for_is_read_in_px4s_order(params, kind):
    assert requested((*params, *[0.0] * (7 - len(params)))) == kind


def test_gyro_calibration_stores_the_still_imus_mean_rate_with_px4s_texts_in_order():
    bench = Bench()
    bias = (0.012, -0.021, 0.004)
    assert bench.command(*GYRO) == m.MAV_RESULT_ACCEPTED
    assert bench.vehicle.texts == []  # after the ack
    out = bench.run(mounted(0, 0, bias), WINDOW_S + 0.5, rng=np.random.default_rng(1))
    assert bench.cal_texts == [
        "calibration started: 2 gyro", "progress <20>", "progress <40>", "progress <60>",
        "progress <80>", "progress <100>", "calibration done: gyro",
    ]  # fmt: skip
    stored = [bench.store.get(f"INS_GYROFFS_{a}") for a in "XYZ"]
    assert stored == pytest.approx(bias, abs=5e-4)
    assert {name for name, _ in bench.changed} == {"INS_GYROFFS_X", "INS_GYROFFS_Y",
                                                   "INS_GYROFFS_Z"}  # fmt: skip
    assert {o.msg.param_id for o in out} >= {"INS_GYROFFS_X", "INS_GYROFFS_Y", "INS_GYROFFS_Z"}
    assert bench.vehicle.feeds[-1].closed and not bench.calibration.running


def test_a_second_gyro_calibration_adds_what_the_first_missed_in_the_imus_own_axes():
    bias = (0.03, 0.01, -0.02)
    bench = Bench(AHRS_TRIM_X=math.radians(4), AHRS_TRIM_Y=math.radians(-3),
                  INS_GYROFFS_X=0.01)  # fmt: skip
    bench.command(*GYRO)
    bench.run(mounted(4, -3, bias), WINDOW_S + 0.5)
    stored = [bench.store.get(f"INS_GYROFFS_{a}") for a in "XYZ"]
    assert stored == pytest.approx(bias, abs=1e-6)  # the offsets are the IMU's own bias


def test_level_calibration_finds_the_mounting_tilt_and_the_driver_then_reads_level():
    bench = Bench(AHRS_TRIM_X=math.radians(1.0))  # a first, partial trim
    assert bench.command(*LEVEL) == m.MAV_RESULT_ACCEPTED
    raw = mounted(3.0, -2.0, (0.001, 0.0, 0.0))
    bench.run(raw, WINDOW_S + 0.5, rng=np.random.default_rng(2))
    assert bench.cal_texts[0] == "calibration started: 2 level"
    assert bench.cal_texts[-1] == "calibration done: level"
    trims = (
        math.degrees(bench.store.get("AHRS_TRIM_X")),
        math.degrees(bench.store.get("AHRS_TRIM_Y")),
    )
    assert trims == pytest.approx((3.0, -2.0), abs=0.05)
    imu = sample(0, raw)
    cal = ImuCalibration.from_params(bench.store.values)
    cal.correct(imu, None, cal.rotation)
    assert (imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2) == pytest.approx((0, 0, -G), abs=0.02)


def test_a_moving_aircraft_or_a_tilted_one_fails_with_the_reason_and_stores_nothing():
    bench = Bench()
    bench.command(*GYRO)
    bench.calibration.tick(0.0)
    for i in range(400):  # rocking at 1 rad/s
        bench.t_us += 10_000
        rocking = ((0.0, 0.0, -G), (math.sin(i / 10), 0.0, 0.0))
        bench.vehicle.feeds[-1].pending.append(sample(bench.t_us, rocking))
        bench.vehicle.snapshot.now_us = bench.t_us
        bench.vehicle.snapshot.imu = Imu(t_us=bench.t_us)
        bench.calibration.tick(0.0)
    assert bench.cal_texts[-1] == "calibration failed: the aircraft moved, hold it still"
    assert bench.changed == []
    bench.command(*LEVEL)
    bench.run(mounted(25.0, 0.0), WINDOW_S + 0.5)
    assert bench.cal_texts[-1] == "calibration failed: tilted 25.0 deg, level the aircraft"
    assert bench.changed == [] and not bench.calibration.running


def test_an_imu_that_goes_quiet_fails_the_calibration():
    bench = Bench()
    bench.command(*GYRO)
    bench.vehicle.feeds.clear()  # its samples never come
    bench.run(mounted(0, 0), 7.0)
    assert bench.cal_texts[-1].startswith("calibration failed: 0 IMU samples")


def test_what_cannot_be_done_is_denied_with_the_reason_qgroundcontrol_shows():
    bench = Bench()
    for params, why in ((ACCEL, "VN-100 factory-calibrated"), ((0, 1), "compasses' own"),
                        ((0, 0, 1), "barometer"), ((0, 0, 0, 0, 0, 1), "no airspeed sensor"),
                        ((0, 0, 0, 0, 0, 0, 1), "no ESC calibration")):  # fmt: skip
        assert bench.command(*params) == m.MAV_RESULT_DENIED
        bench.calibration.tick(0.0)
        assert bench.cal_texts[-1].startswith("calibration failed: ") and why in bench.cal_texts[-1]
    bench.vehicle.snapshot.health = SystemHealth(flight_running=1)
    assert bench.command(*GYRO) == m.MAV_RESULT_DENIED
    bench.calibration.tick(0.0)
    assert bench.cal_texts[-1] == "calibration failed: disarm first"
    assert bench.vehicle.feeds == []  # nothing started


def test_without_fresh_imu_samples_or_an_imu_driver_nothing_starts():
    bench = Bench()
    bench.vehicle.snapshot.now_us += 5_000_000
    assert bench.command(*GYRO) == m.MAV_RESULT_DENIED
    bench.calibration.tick(0.0)
    assert bench.cal_texts[-1] == "calibration failed: no IMU samples"
    bare = Calibration(RecordingVehicle(), ParamsService(new_encoder(1), ParamStore(()), 1))
    assert not bare.has_imu()


def test_cancel_stops_a_calibration_and_all_zero_is_accepted_either_way():
    bench = Bench()
    assert bench.command(*CANCEL) == m.MAV_RESULT_ACCEPTED  # nothing under way: radio's end
    bench.command(*GYRO)
    assert bench.command(*LEVEL) == m.MAV_RESULT_TEMPORARILY_REJECTED  # one at a time
    bench.run(mounted(0, 0), 1.0)
    assert bench.command(*CANCEL) == m.MAV_RESULT_ACCEPTED
    bench.run(mounted(0, 0), WINDOW_S)
    assert bench.cal_texts[-1] == "calibration cancelled" and bench.changed == []
    assert bench.vehicle.feeds[-1].closed


def test_the_radio_pages_start_is_accepted_and_copy_trims_refused():
    bench = Bench()
    assert bench.command(0, 0, 0, 1) == m.MAV_RESULT_ACCEPTED
    assert bench.command(0, 0, 0, 2) == m.MAV_RESULT_DENIED
    assert "Copy trims" in bench.vehicle.texts[-1]
    assert bench.command(2) == m.MAV_RESULT_UNSUPPORTED  # param1 2: no calibration


def storage(*params: float) -> CommandArgs:
    full = (*params, *[0.0] * (7 - len(params)))
    return CommandArgs(m.MAV_CMD_PREFLIGHT_STORAGE, full, 0, GCS)


def test_the_sensors_pages_factory_reset_puts_the_calibration_back_to_its_defaults():
    bench = Bench(AHRS_TRIM_X=0.05, INS_GYROFFS_Z=0.01)
    assert bench.storage.storage(storage(3, -1)).result == m.MAV_RESULT_ACCEPTED
    out = bench.calibration.tick(0.0)
    assert (bench.store.get("AHRS_TRIM_X"), bench.store.get("INS_GYROFFS_Z")) == (0.0, 0.0)
    assert {o.msg.param_id for o in out} >= {"AHRS_TRIM_X", "INS_GYROFFS_Z"}
    bench.vehicle.snapshot.health = SystemHealth(flight_running=1)
    assert bench.storage.storage(storage(3, -1)).result == m.MAV_RESULT_DENIED


def test_reset_all_to_defaults_as_qgroundcontrol_sends_it(tmp_path):
    bench = Bench(AHRS_TRIM_X=0.05, INS_GYROFFS_Z=0.01)
    bench.store.path = tmp_path / "params.json"
    bench.vehicle.snapshot.health = SystemHealth(flight_running=1)
    assert bench.storage.storage(storage(2, -1)).result == m.MAV_RESULT_DENIED
    assert bench.store.get("AHRS_TRIM_X") == 0.05  # nothing changed under the flight
    bench.vehicle.snapshot.health = SystemHealth(flight_running=0)
    assert bench.storage.storage(storage(2, -1)).result == m.MAV_RESULT_ACCEPTED
    assert (bench.store.get("AHRS_TRIM_X"), bench.store.get("INS_GYROFFS_Z")) == (0.0, 0.0)
    assert ParamStore(IMU_CAL_PARAMS, bench.store.path).get("AHRS_TRIM_X") == 0.0  # stored
    assert bench.changed == [(RELOAD_ALL, 0.0)]  # the owners read the stored values again
    assert bench.vehicle.texts[-1] == "Parameters reset to defaults: 2 changed"
    sent = [(o.msg.param_id, o.msg.param_value, o.to) for o in bench.params.tick(0.0)]
    assert sent == [("AHRS_TRIM_X", 0.0, None), ("INS_GYROFFS_Z", 0.0, None)]  # to every GCS
    assert bench.storage.storage(storage(1)).result == m.MAV_RESULT_ACCEPTED  # stored as set
    assert bench.storage.storage(storage(5)).result == m.MAV_RESULT_UNSUPPORTED


def test_sys_autoconfig_2_resets_too_but_not_while_armed():
    bench = Bench(AHRS_TRIM_X=0.05)
    autoconfig = ParamDecl("SYS_AUTOCONFIG", 0.0, 0.0, 2.0, values=((0.0, "keep"), (2.0, "reset")))
    bench.store = ParamStore((*IMU_CAL_PARAMS, autoconfig))
    bench.store.set("AHRS_TRIM_X", 0.05)
    bench.params = ParamsService(new_encoder(1, 1), bench.store, 1, 1)
    StorageCommands(bench.vehicle, bench.params, bench.calibration).register(
        CommandService(new_encoder(1, 1), 1)
    )
    bench.vehicle.snapshot.health = SystemHealth(flight_running=1)
    with pytest.raises(ParamError, match="disarm first"):
        bench.params.write("SYS_AUTOCONFIG", 2.0)
    assert bench.store.get("AHRS_TRIM_X") == 0.05
    bench.vehicle.snapshot.health = SystemHealth(flight_running=0)
    out = bench.params.write("SYS_AUTOCONFIG", 2.0)
    assert [(o.msg.param_id, o.msg.param_value) for o in out] == [("SYS_AUTOCONFIG", 0.0)]
    assert bench.store.get("AHRS_TRIM_X") == 0.0
