"""A plug-in chained to the one that feeds it in a composed process: run on that one's
wake-up (its thread), restarted alone when it raises there, and still acting on its own
timeouts when its input stops."""

from __future__ import annotations

import time
from dataclasses import replace

from companion.messages import PluginState
from tests.support.configs import plugin, vehicle_config
from tests.support.vehicle import wait_for

TICKER = "tests.support.chained_plugins:ThreadTicker"
CHAINED = "tests.support.chained_plugins:ChainedRelay"
BURNER = "tests.support.chained_plugins:ChainedBurner"


def in_one_process(*entries):
    return vehicle_config("chain", *(replace(e, process="core") for e in entries))


def states(reader, want: int, timeout_s: float = 20.0) -> list:
    """At least ``want`` navigation values with a sample's count (roll > 0)."""
    got: list = []

    def enough() -> bool:
        got.extend(v for v in reader.drain() if v.roll_rad > 0)
        return len(got) >= want

    wait_for(enough, timeout_s, f"{want} relayed samples")
    return got


def test_a_chained_plugin_runs_on_the_wake_up_of_the_plugin_that_publishes_its_input(
    vehicle_factory,
):
    vehicle = vehicle_factory(
        in_one_process(plugin("imu", TICKER, rate_hz=100.0), plugin("relay", CHAINED))
    )
    nav = vehicle.bus.latest_reader("nav/state", keep=64)
    states(nav, 20)  # the first may be taken on its own thread, before the chain runs
    relayed = states(nav, 100)
    on_producer = [s for s in relayed if s.pitch_rad == s.yaw_rad]
    assert len(on_producer) >= 0.95 * len(relayed), "steps ran on the relay's own thread"
    counts = [int(s.roll_rad) for s in relayed]
    assert counts == list(range(counts[0], counts[0] + len(counts))), "a sample was skipped"
    assert vehicle.row("relay").state == PluginState.RUNNING


def test_a_chained_plugin_that_raises_is_restarted_alone_while_its_producer_goes_on(
    vehicle_factory,
):
    vehicle = vehicle_factory(
        in_one_process(plugin("imu", TICKER, rate_hz=100.0), plugin("relay", CHAINED, crash_at=60))
    )
    nav = vehicle.bus.latest_reader("nav/state", keep=64)
    pid = vehicle.wait_running("imu")
    wait_for(lambda: (r := vehicle.row("relay")) and r.restarts >= 1, 20, "the relay restarted")
    after = states(nav, 50)
    assert max(s.roll_rad for s in after) > 60, "no sample relayed after the crash"
    imu = vehicle.row("imu")
    assert (imu.pid, imu.restarts, imu.state) == (pid, 0, PluginState.RUNNING)
    assert vehicle.row("relay").pid == pid, "the process itself did not die"


def test_a_chained_plugin_acts_on_its_own_timeouts_when_its_producer_falls_silent(
    vehicle_factory,
):
    vehicle = vehicle_factory(
        in_one_process(plugin("imu", TICKER, rate_hz=100.0, count=300), plugin("relay", CHAINED))
    )
    nav = vehicle.bus.latest_reader("nav/state", keep=64)
    producer_thread = states(nav, 30)[-1].yaw_rad

    def timed_out():
        return next((v for v in nav.drain() if v.roll_rad == -1.0), None)

    # The ticker stops after 300 samples (3 s); the relay's own wait then ends empty.
    silent = wait_for(timed_out, 15, "the relay's own timeout after the IMU fell silent")
    assert silent.pitch_rad != producer_thread, "the timeout ran on the producer's thread"


def test_each_plugin_of_a_chain_is_charged_its_own_cpu(vehicle_factory):
    # imu -> relay -> burner, all on the IMU's thread: the burner's 3 ms a state at 100 Hz
    # (a third of a core; less on a busy machine, where fewer states come) shows in its own
    # row, not in the IMU's or the relay's, whose own work (a tick, a relay step, the
    # chain's calls) is about 1 % of a core idle and grows on a busy machine (5.5 % beside
    # two CPU-bound jobs: over the 5 % this test allowed them against a 1 ms burn).
    vehicle = vehicle_factory(
        in_one_process(
            plugin("imu", TICKER, rate_hz=100.0),
            plugin("relay", CHAINED),
            plugin("burner", BURNER, burn_ms=3.0),
        )
    )
    nav = vehicle.bus.latest_reader("nav/state", keep=64)
    states(nav, 100)

    def cpu() -> dict[str, float]:
        rows = {n: vehicle.row(n) for n in ("imu", "relay", "burner")}
        return {n: r.cpu_pct for n, r in rows.items() if r is not None}

    # The backlog of states the burner found at its start is burnt at a whole core first.
    wait_for(lambda: 10.0 < cpu().get("burner", 0.0) < 45.0, 30, "the burner at its rate")
    time.sleep(1.1)  # the rows of the second that ended it also hold the plug-ins' init
    for _ in range(3):  # each second's rows, once a second
        share = cpu()
        assert 10.0 < share["burner"] < 45.0, share
        assert 0.0 <= share["imu"] < share["burner"] / 4, share
        assert 0.0 <= share["relay"] < share["burner"] / 4, share
        time.sleep(1.0)


def test_a_sample_published_without_waking_goes_with_the_next_one(vehicle_factory):
    # The IMU wakes its readers on every other sample (its wake_hz): the chained relay
    # steps once per two samples, and relays every one of them.
    vehicle = vehicle_factory(
        in_one_process(plugin("imu", TICKER, rate_hz=100.0, wake_every=2), plugin("relay", CHAINED))
    )
    nav = vehicle.bus.latest_reader("nav/state", keep=64)
    states(nav, 20)
    stats = vehicle.bus.queue_reader("system/plugin_stats")
    relayed = states(nav, 200)
    counts = [int(s.roll_rad) for s in relayed]
    assert counts == list(range(counts[0], counts[0] + len(counts))), "a sample was skipped"
    steps: dict[str, list[int]] = {}
    wait_for(
        lambda: (
            [steps.setdefault(m.name.decode(), []).append(m.steps) for m in stats.drain()]
            and all(len(steps.get(n, [])) >= 2 for n in ("imu", "relay"))
        ),
        10,
        "two counters of each",
    )
    imu, relay = (steps[n][-1] - steps[n][0] for n in ("imu", "relay"))
    assert 0.4 * imu <= relay <= 0.6 * imu, (imu, relay)


def test_the_flight_path_of_a_composed_process_is_up_before_its_other_plugins(
    vehicle_factory,
):
    """A composed process (started, or restarted after a kill in the air) inits its flight
    path first: a plug-in whose init holds the interpreter's lock for 1.5 s, listed first,
    does not hold up the IMU's and the chained relay's inits, whose first counters come
    before its own, and the samples then flow through the chain."""
    vehicle = vehicle_factory(
        in_one_process(
            plugin("slow", "tests.support.chained_plugins:SlowInit", hold_s=1.5),
            plugin("imu", TICKER, rate_hz=100.0),
            plugin("relay", CHAINED),
        )
    )
    stats = vehicle.bus.queue_reader("system/plugin_stats")
    first: list[bytes] = []

    def all_up() -> bool:
        first.extend(s.name for s in stats.drain() if s.name not in first)
        return len(first) == 3

    wait_for(all_up, 30, "the three plug-ins' first counters")
    assert first[-1] == b"slow", first
    states(vehicle.bus.latest_reader("nav/state", keep=64), 20)
