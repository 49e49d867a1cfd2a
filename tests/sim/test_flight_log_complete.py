"""The flight log holds every sample of every channel it records, though the logger wakes
ten times a second (not once per sample) and drains what queued meanwhile: a mission flown
in real time in ``companion sim``, each logged topic's rows against the samples the test's
own readers saw published, stamp for stamp."""

from __future__ import annotations

import time
from pathlib import Path

from pyulog import ULog

from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.flight_log import topic_name
from companion.messages.channels import CHANNELS
from tests.sim.sim_run import finish, start_sim
from tests.support.vehicle import REPO, wait_for

PLAN = str(REPO / "qgc_plans" / "square.plan")
DURATION_S = 25.0
# The fast channels, where a batch too large for a reader's buffer would lose samples
# (100 Hz IMU and rangefinder, 50 Hz navigation, controller and servos), and slower ones.
CHECKED = (
    "sensors/imu", "sensors/range", "sensors/rc", "nav/state", "control/actuators",
    "actuators/servos", "control/status", "sensors/compass", "sensors/baro", "sensors/gps",
    "sensors/battery",
)  # fmt: skip


class Published:
    """Every sample of the checked channels, by t_us, as the test's own readers see them."""

    def __init__(self, namespace: str) -> None:
        self.bus = BusNode(namespace, "test")
        self.readers = {
            name: self.bus.queue_reader(name)
            if CHANNELS[name].pattern == "queue"
            else self.bus.latest_reader(name, keep=CHANNELS[name].depth)
            for name in CHECKED
        }
        self.stamps: dict[str, list[int]] = {name: [] for name in CHECKED}

    def read(self) -> None:
        for name, reader in self.readers.items():
            self.stamps[name] += [int(msg.t_us) for msg in reader.drain()]
            assert reader.lost == 0, f"the test's reader of {name} fell behind"

    def close(self) -> None:
        self.bus.close()


def test_every_published_sample_is_in_the_log_with_its_own_stamp(tmp_path: Path):
    proc, namespace, _ = start_sim(
        tmp_path, "udpout://127.0.0.1:9", "--speed", "1", "--plan", PLAN, "--airborne",
        "--start-at", "3", "--duration", str(DURATION_S),
    )  # fmt: skip
    published = None
    try:
        wait_for(lambda: (tmp_path / "state").exists(), 60, "the vehicle's state directory")
        published = Published(namespace)
        while proc.poll() is None:
            published.read()
            time.sleep(0.01)
        published.read()
    finally:
        if published is not None:
            published.close()
            if proc.poll() is not None:
                # The vehicle ended first: the channels were left to the test's readers.
                cleanup_namespace(namespace)
        finish(proc, namespace, 120)
    logs = sorted((tmp_path / "state" / "logs").glob("*armed.ulg"))
    assert logs, "no flight log"
    ulog = ULog(str(logs[-1]))
    for name in CHECKED:
        logged = [int(t) for t in ulog.get_dataset(topic_name(name)).data["timestamp"]]
        seen = published.stamps[name]
        assert len(logged) > 0 and len(seen) > 0, name
        # The test's readers joined after start-up and the log closed at the end: compare
        # what both could see, between the later first and the earlier last stamp.
        first, last = max(logged[0], seen[0]), min(logged[-1], seen[-1])
        window_logged = [t for t in logged if first <= t <= last]
        window_seen = [t for t in seen if first <= t <= last]
        assert last - first > 10e6, (name, first, last)  # most of the flight
        assert window_logged == window_seen, (name, len(window_logged), len(window_seen))
