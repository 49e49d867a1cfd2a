"""The navigator's time-ordering buffer (companion/navigation/sample_order.py)."""

from __future__ import annotations

from companion.messages import Baro, GpsFix, Imu
from companion.navigation.sample_order import SampleOrder


def _kinds(samples) -> list[tuple[str, int]]:
    return [(type(s).__name__, s.t_us) for s in samples]


def test_a_fix_that_overtakes_the_imu_waits_for_it_and_follows_it():
    order = SampleOrder()
    assert _kinds(order.push([Imu(t_us=0)])) == [("Imu", 0)]
    assert order.push([GpsFix(t_us=10_000)]) == []  # the IMU has not reached 10 ms yet
    ready = order.push([Imu(t_us=10_000), Imu(t_us=20_000)])
    assert _kinds(ready) == [("Imu", 10_000), ("GpsFix", 10_000), ("Imu", 20_000)]


def test_the_result_does_not_depend_on_how_the_samples_were_batched():
    samples = [Imu(t_us=0), Baro(t_us=5_000), Imu(t_us=10_000), GpsFix(t_us=10_000),
               Baro(t_us=15_000), Imu(t_us=20_000)]  # fmt: skip
    one_batch = _kinds(SampleOrder().push(samples))
    order, piecewise = SampleOrder(), []
    for batch in ([samples[3], samples[1]], [samples[0]], [samples[4], samples[2], samples[5]]):
        piecewise += _kinds(order.push(batch))
    assert piecewise == one_batch
    assert one_batch == [("Imu", 0), ("Baro", 5_000), ("Imu", 10_000), ("GpsFix", 10_000),
                         ("Baro", 15_000), ("Imu", 20_000)]  # fmt: skip


def test_aiding_flows_on_when_the_imu_goes_quiet():
    order = SampleOrder(max_hold_us=200_000)
    order.push([Imu(t_us=0)])
    assert order.push([GpsFix(t_us=100_000)]) == []
    ready = order.push([GpsFix(t_us=300_000)])  # 0.2 s newer: the first is let go
    assert _kinds(ready) == [("GpsFix", 100_000)]
