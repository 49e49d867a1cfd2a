"""Data crosses real processes through both bus patterns, and losses are counted."""

from __future__ import annotations

import ctypes
import random
import subprocess
import sys
import textwrap
import time

import pytest

from companion.bus.namespace import cleanup_namespace, iox_dir
from companion.bus.node import BusNode
from companion.messages import CHANNELS, Imu, Magnetometer, NavState
from tests.support.configs import PUBLISH_ONCE, plugin, vehicle_config
from tests.support.vehicle import REPO, assert_clean, unique_namespace, wait_for

WRITER = textwrap.dedent(
    """
    import sys, time
    from companion.bus.node import BusNode
    from companion.messages import Imu, NavState
    ns, count, subscribers = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    with BusNode(ns, "writer") as bus:
        imu, nav = bus.writer("sensors/imu"), bus.writer("nav/state")
        ready = bus.latest_reader("sim/clock")
        ready.wait(10.0)          # the test says when its readers are connected
        for i in range(count):
            imu.publish(Imu(t_us=i, ax_m_s2=i * 0.5))
            nav.publish(NavState(t_us=i, yaw_rad=i * 0.001))
        # Stay alive (a Latest value goes with its writer) until the test has read: it
        # says so with clock 2. wait() returns at once while clock 1 is still the newest.
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:
            clock = ready.wait(0.1)
            if clock is not None and clock.t_us == 2:
                break
    """
)


@pytest.fixture
def namespace():
    ns = unique_namespace("bus")
    yield ns
    cleanup_namespace(ns)
    assert_clean(ns)


def run_writer(ns: str, count: int) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, "-c", WRITER, ns, str(count), "1"], cwd=REPO)


def test_every_channels_payload_arrives_byte_for_byte(namespace):
    """The payload is copied in and out as raw bytes laid over the sample: any pattern of
    bytes in any registered type, arrays and nested structures included, comes out as it
    went in."""
    rng = random.Random(46)
    with BusNode(namespace, "writer") as out, BusNode(namespace, "reader") as into:
        for name, chan in CHANNELS.items():
            writer = out.writer(name)
            reader = into.reader(name)
            msg = chan.type()
            raw = bytes(rng.randrange(256) for _ in range(ctypes.sizeof(msg)))
            ctypes.memmove(ctypes.addressof(msg), raw, len(raw))
            writer.publish(msg)
            got = list(reader.drain()) if chan.pattern == "queue" else [reader.get()]
            assert [bytes(m) for m in got] == [raw], name


def test_queue_delivers_every_sample_in_order_and_latest_the_newest(namespace):
    with BusNode(namespace, "reader") as bus:
        queue = bus.queue_reader("sensors/imu")
        latest = bus.latest_reader("nav/state")
        go = bus.writer("sim/clock")
        writer = run_writer(namespace, 50)
        try:
            from companion.messages import SimClock

            # Wake the writer until it has connected and started; then read as it writes.
            received: list[Imu] = []
            for _ in range(200):
                go.publish(SimClock(t_us=1))
                received += queue.take(timeout_s=0.05)
                if len(received) >= 50:
                    break
            # nav/state's last sample is written just after the last IMU one: wait for it.
            newest = wait_for(
                lambda: (n := latest.get()) is not None and n.t_us == 49 and n, 5, "nav 49"
            )
        finally:
            go.publish(SimClock(t_us=2))
            writer.wait(timeout=10)
    assert [m.t_us for m in received] == list(range(50))
    assert received[7].ax_m_s2 == 3.5
    assert queue.lost == 0
    assert newest is not None and newest.t_us == 49
    assert newest.yaw_rad == pytest.approx(0.049)


def test_slow_reader_loses_the_oldest_and_counts_the_loss(namespace):
    depth = 64  # sensors/imu is registered with depth 64
    with BusNode(namespace, "slow-reader") as bus:
        queue = bus.queue_reader("sensors/imu")
        writer = bus.writer("sensors/imu")
        writer.publish(Imu(t_us=0))
        assert [m.t_us for m in queue.take()] == [0]
        for i in range(1, 201):  # the reader falls behind while these are written
            writer.publish(Imu(t_us=i))
        got = queue.take()
    assert [m.t_us for m in got] == list(range(201 - depth, 201))
    assert queue.lost == 200 - depth


def test_newest_reader_of_a_queue_sees_only_the_newest_and_counts_no_loss(namespace):
    with BusNode(namespace, "newest") as bus:
        every = bus.queue_reader("sensors/imu")
        newest = bus.newest_reader("sensors/imu")
        writer = bus.writer("sensors/imu")
        assert newest.get() is None
        for i in range(1, 11):
            writer.publish(Imu(t_us=i))
        first = newest.get()
        # Nothing newer: the newest stays what it was, as a Latest reader's does.
        again = newest.get()
        writer.publish(Imu(t_us=11))
        later = newest.get()
        assert [m.t_us for m in every.take()] == list(range(1, 12))
        lost = bus.total_lost()
    assert first is not None and first.t_us == 10
    assert again is not None and again.t_us == 10
    assert later is not None and later.t_us == 11
    assert newest.received == 2 and lost == 0


def test_a_gated_reader_ends_a_wait_only_while_its_gate_is_open(namespace):
    with BusNode(namespace, "gated") as bus:
        nav, acks = bus.latest_reader("nav/state"), bus.queue_reader("link/command_acks")
        waiter = bus.gated_waiter(nav, [acks])
        writer = bus.writer("nav/state")
        writer.publish(NavState(t_us=1))
        shut, _ = waiter.wait_with_fds(0.05, [], gate_open=False)  # ends by its timeout
        opened, _ = waiter.wait_with_fds(10.0, [], gate_open=True)  # ends on the state
        first = nav.get()
        writer.publish(NavState(t_us=2))
        again, _ = waiter.wait_with_fds(10.0, [], gate_open=True)
        second = nav.get()
        waiter.close()
    assert shut == [] and opened == [nav] and again == [nav]
    assert first is not None and first.t_us == 1
    assert second is not None and second.t_us == 2


def test_latest_reader_that_joins_late_still_gets_the_newest_value(namespace):
    with BusNode(namespace, "w") as bus_w, BusNode(namespace, "r") as bus_r:
        writer = bus_w.writer("nav/state")
        for i in range(5):
            writer.publish(NavState(t_us=i))
        late = bus_r.latest_reader("nav/state")
        writer.publish(NavState(t_us=99))
        value = late.wait(2.0)
    assert value is not None and value.t_us == 99


def test_a_value_published_once_reaches_a_reader_that_connects_much_later(vehicle_factory):
    vehicle = vehicle_factory(vehicle_config("once", plugin("once", PUBLISH_ONCE)))
    vehicle.wait_running("once")
    time.sleep(0.5)  # long after the only publication
    late = vehicle.bus.latest_reader("nav/state")
    value = wait_for(late.get, 2.0, "the value published before the reader existed")
    assert value.yaw_rad == pytest.approx(0.25)


def test_first_waits_for_the_value_a_writer_published_before_the_reader_joined(vehicle_factory):
    vehicle = vehicle_factory(vehicle_config("once", plugin("once", PUBLISH_ONCE)))
    vehicle.wait_running("once")
    late = vehicle.bus.latest_reader("nav/state")
    wait_for(late.writers, 30.0, "the plug-in's writer")
    # Handed over when the writer's process next updates its connections: first() waits.
    value = late.first(30.0)
    assert value is not None and value.yaw_rad == pytest.approx(0.25)


def test_first_without_a_writer_is_none(namespace):
    with BusNode(namespace, "r") as bus:
        nobody = bus.latest_reader("vehicle/status")
        assert nobody.writers() == 0
        assert nobody.first(30.0) is None


def test_a_closed_node_leaves_nothing_though_its_ports_are_still_referenced(namespace):
    """A test or tool that keeps its readers and writers in variables after closing the
    node must not keep the node alive: while it is, nothing of the namespace can be
    removed, and its files outlive the process."""
    bus = BusNode(namespace, "held")
    ports = (bus.writer("link/commands"), bus.queue_reader("link/command_acks"))
    nav = bus.latest_reader("nav/state")
    assert nav.wait(0.05) is None
    bus.close()
    cleanup_namespace(namespace)
    assert_clean(namespace)
    assert ports and nav  # still referenced until here


def test_a_waiter_on_one_trigger_sleeps_for_it_alone_and_never_for_ever(namespace):
    """One trigger waits on its own listener, whose zero timeout would mean for ever: a
    zero (or negative) timeout returns at once, a sample on the other reader wakes nobody,
    and the trigger's sample does."""
    with BusNode(namespace, "one") as bus:
        imu, mag = bus.queue_reader("sensors/imu"), bus.queue_reader("sensors/mag")
        waiter = bus.waiter([imu, mag], triggers=[imu])
        imu_out, mag_out = bus.writer("sensors/imu"), bus.writer("sensors/mag")
        started = time.monotonic()
        assert waiter.wait(0.0) == [] and waiter.wait(-1.0) == []
        assert time.monotonic() - started < 1.0
        mag_out.publish(Magnetometer(t_us=1))
        started = time.monotonic()
        assert waiter.wait(0.3) == [mag]  # slept its whole timeout: mag is not a trigger
        assert time.monotonic() - started >= 0.25
        list(mag.drain())
        imu_out.publish(Imu(t_us=2))
        started = time.monotonic()
        assert waiter.wait(30.0) == [imu]
        assert time.monotonic() - started < 10.0
        waiter.close()


def test_a_killed_processs_node_leaves_no_directory_behind(namespace):
    """A vehicle killed outright (kill -9 of the supervisor, which its service restarts)
    leaves its nodes' directories; the next start's cleanup removes them whole, with the
    namespace's folder of iceoryx2 files: nothing of it stays in /dev/shm."""
    folder = iox_dir(namespace)
    code = (
        "import sys, time\nfrom companion.bus.node import BusNode\n"
        "bus = BusNode(sys.argv[1], 'doomed'); w = bus.writer('link/commands')\n"
        "print('up', flush=True); time.sleep(60)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code, namespace], cwd=REPO, stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout is not None and proc.stdout.readline() == "up\n"
    assert any((folder / "nodes").iterdir()), "the node made its directory"
    proc.kill()
    proc.wait()
    cleanup_namespace(namespace)
    assert_clean(namespace)
    assert not folder.exists(), sorted(folder.rglob("*"))


def test_before_gives_the_newest_value_older_than_a_time_whatever_came_since(namespace):
    """The flight controller reads the rangefinder measured before its navigation solution:
    the reading of the solution's own instant, there or not yet, changes nothing."""
    from companion.messages import RangeReading

    with BusNode(namespace, "w") as bus_w, BusNode(namespace, "r") as bus_r:
        reader = bus_r.latest_reader("sensors/range", keep=4)
        writer = bus_w.writer("sensors/range")
        assert reader.writers() == 1 and bus_r.queue_reader("sensors/imu").writers() == 0
        assert reader.before(10) is None
        for t_us in (10, 20):
            writer.publish(RangeReading(t_us=t_us, distance_m=t_us / 10))
        wait_for(lambda: reader.has_samples(), 5, "the readings")
        without = reader.before(30)
        writer.publish(RangeReading(t_us=30, distance_m=3.0))  # the solution's own instant
        wait_for(lambda: reader.has_samples(), 5, "the reading at 30")
        with_it = reader.before(30)
        later = reader.before(40)
    assert without is not None and with_it is not None and later is not None
    assert (without.t_us, with_it.t_us, with_it.distance_m) == (20, 20, 2.0)
    assert later.t_us == 30


def test_a_killed_processs_node_is_cleaned_while_others_of_its_bus_live_on(namespace):
    """A plug-in process killed outright leaves a dead node among living ones (the
    supervisor's, the other plug-ins'): the cleanup removes that node alone, and the
    living node's channel still carries samples to a reader that joins afterwards."""
    import iceoryx2 as iox2

    from companion.bus.namespace import cleanup_dead_nodes, make_config

    code = (
        "import sys, time\nfrom companion.bus.node import BusNode\n"
        "bus = BusNode(sys.argv[1], 'doomed'); r = bus.latest_reader('nav/state')\n"
        "print('up', flush=True); time.sleep(60)\n"
    )
    with BusNode(namespace, "alive") as bus:
        nav = bus.writer("nav/state")
        proc = subprocess.Popen(
            [sys.executable, "-c", code, namespace], cwd=REPO, stdout=subprocess.PIPE, text=True
        )
        assert proc.stdout is not None and proc.stdout.readline() == "up\n"
        proc.kill()
        proc.wait()

        def states() -> list[type]:
            return [type(s) for s in iox2.Node.list(iox2.ServiceType.Ipc, make_config(namespace))]

        assert iox2.NodeState.Dead in states()
        assert cleanup_dead_nodes(namespace) == 1
        assert iox2.NodeState.Dead not in states()
        assert states().count(iox2.NodeState.Alive) == 1
        reader = bus.latest_reader("nav/state")
        nav.publish(NavState(t_us=7))
        got = wait_for(reader.get, 5.0, "the sample after the cleanup")
        assert got is not None and got.t_us == 7
