"""The navigator's time-ordering buffer (companion/navigation/sample_order.py)."""

from __future__ import annotations

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer
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


def test_aiding_samples_of_one_instant_go_in_the_same_order_whichever_process_came_first():
    # Each driver is its own process: at 10 ms the compass may reach the navigator before
    # or after the IMU's magnetometer, and before or after the IMU sample itself.
    def fed(arrivals: list[list]) -> list[tuple[str, int]]:
        order, out = SampleOrder(), []
        for batch in arrivals:
            out += _kinds(order.push(batch))
        return out

    imu0, imu1, imu2 = Imu(t_us=0), Imu(t_us=10_000), Imu(t_us=20_000)
    mag, compass = Magnetometer(t_us=10_000), Compass(t_us=10_000)
    mag_first = fed([[imu0], [imu1, mag], [compass], [imu2]])
    compass_first = fed([[imu0], [compass], [imu1], [mag], [imu2]])
    together = fed([[imu0], [imu1, compass, mag, imu2]])
    assert mag_first == compass_first == together
    assert mag_first == [("Imu", 0), ("Imu", 10_000), ("Magnetometer", 10_000),
                         ("Compass", 10_000), ("Imu", 20_000)]  # fmt: skip


def test_aiding_flows_on_when_the_imu_goes_quiet():
    order = SampleOrder(max_hold_us=200_000)
    order.push([Imu(t_us=0)])
    assert order.push([GpsFix(t_us=100_000)]) == []
    ready = order.push([GpsFix(t_us=300_000)])  # 0.2 s newer: the first is let go
    assert _kinds(ready) == [("GpsFix", 100_000)]


def test_fixes_that_arrive_late_are_still_used_and_never_look_like_an_outage():
    # The GPS driver's process runs late: each fix reaches the navigator 0.6 s after its
    # time stamp, behind 60 IMU samples. The navigator still uses every fix (against its
    # state of that time) and never says dead reckoning outside the real outage.
    from companion.messages import NavFlags
    from companion.navigation.offline import InsEkfRunner, true_headings
    from ground.simulation import evaluation
    from tests.unit.navigation.flights import DECLINATION, OUTAGE, flight

    samples = list(true_headings(evaluation.messages(flight()), DECLINATION))
    late_us = 600_000
    arrivals = sorted(
        ((s.t_us + (late_us if isinstance(s, GpsFix) else 0), i, s) for i, s in enumerate(samples)),
        key=lambda a: (a[0], a[1]),
    )
    runner, order = InsEkfRunner(DECLINATION), SampleOrder()
    fixes = accepted = 0
    dead_reckoning_outside_outage = 0
    start, end = OUTAGE[0] * 1e6, (OUTAGE[0] + OUTAGE[1] + 3) * 1e6
    for _, _, sample in arrivals:
        for ready in order.push([sample]):
            before = runner.nav.last_gps_us
            runner.feed(ready)
            if isinstance(ready, GpsFix) and ready.fix_type >= 3 and runner.nav.aligned:
                fixes += 1
                accepted += runner.nav.last_gps_us != before
            if isinstance(ready, Imu) and runner.nav.aligned and not start <= ready.t_us <= end:
                state = runner.nav.state()
                dead_reckoning_outside_outage += bool(state.flags & NavFlags.DEAD_RECKONING)
    assert fixes > 500 and accepted >= 0.98 * fixes
    assert dead_reckoning_outside_outage == 0


class _Channel:
    """A reader of one channel; ``then`` runs once its first sample has been read (what the
    simulator and the other drivers do meanwhile)."""

    def __init__(self, *samples) -> None:
        self.samples = list(samples)
        self.then = None

    def drain(self):
        while self.samples:
            yield self.samples.pop(0)
            if self.then is not None:
                self.then, then = None, self.then
                then()

    def pending(self):
        return list(self.drain())

    def has_samples(self) -> bool:
        return bool(self.samples)


def test_a_fix_published_while_the_imu_is_read_is_fed_before_the_next_imu_sample():
    # nav.ins_ekf woken by the IMU sample of 0 ms: while it reads it, the GPS driver
    # publishes its fix of 0 ms and the simulator, having waited for that fix, writes the
    # next frame, whose IMU sample of 10 ms the same read takes. The fix must go in before it.
    from companion.plugins.nav.ins_ekf import received

    imu, gps = _Channel(Imu(t_us=0)), _Channel()
    heading_and_baro = [_Channel(), _Channel(), _Channel()]

    def next_frame() -> None:
        gps.samples.append(GpsFix(t_us=0))
        imu.samples.append(Imu(t_us=10_000))

    imu.then = next_frame
    fed = _kinds(SampleOrder().push(received([imu, gps, *heading_and_baro])))
    assert fed == [("Imu", 0), ("GpsFix", 0), ("Imu", 10_000)]
