"""A composed process's chain charges each plug-in the CPU of its own steps, at every moment.

The IMU's thread runs the relay's step and, after it, the burner's: the thread's CPU clock
counts all three, and the chain moves each follower's share from the IMU's row to its own.
Each row is read on another thread once a second, whenever that falls, so no row may show
another's work even for a moment (a relay read during a follower's long step showed 43 %).
"""

from __future__ import annotations

import functools
import time

import pytest

from companion.exec_control.chain import ChainLink, run_followers


def _burn(seconds: float) -> None:
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass


class _Reader:
    def has_samples(self) -> bool:
        return True

    def take_notifications(self) -> bool:
        return True


class _Host:
    """What the chain uses of a PluginHost: its step, its followers, its moved CPU."""

    def __init__(self, burn_s: float, watched: list[_Host] | None = None) -> None:
        self.burn_s, self.watched = burn_s, watched or []
        self.cpu_moved_s = 0.0
        self.seen: list[float] = []  # the watched rows' moved CPU, during this step
        self.after_step = lambda payer=None: (None, 0.0)
        self.bus = self

    def reader_of(self, trigger: str) -> _Reader:
        return _Reader()

    def step_once(self) -> None:
        _burn(self.burn_s)
        self.seen += [h.cpu_moved_s for h in self.watched]


def _chained(name: str, host: _Host, followers: list[ChainLink]) -> ChainLink:
    link = ChainLink(name, "nav/state", 1.0)
    link.host = host  # type: ignore[assignment]
    host.after_step = functools.partial(run_followers, followers, host)
    return link


def test_each_row_holds_its_own_steps_during_and_after_the_chain():
    imu, relay, burner = _Host(0.0), _Host(0.002), _Host(0.030)
    watcher = _Host(0.0, watched=[relay])  # reads the relay's row after the burner's step
    links = [_chained("burner", burner, []), _chained("watcher", watcher, [])]
    relay_link = _chained("relay", relay, links)
    cpu_after, took = run_followers([relay_link], imu)  # type: ignore[arg-type]
    assert cpu_after is not None and took == pytest.approx(0.032, abs=0.005)
    # Read after the burner's long step, the relay's row never showed minus that step.
    assert watcher.seen[0] > -0.001, watcher.seen
    assert relay.cpu_moved_s == pytest.approx(0.002, abs=0.001)
    assert burner.cpu_moved_s == pytest.approx(0.030, abs=0.002)
    assert imu.cpu_moved_s == pytest.approx(-took, abs=1e-9)
