"""The CPU quota benchmarks/cpu_quota.py confines the vehicle with: a process that joins
before it starts is held to its share of a core with its children, and nothing is left."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from tests.support.cpu_quota import CPU_ROOT, CpuQuota, period_and_quota, unusable_reason

# A parent that forks a child and both spin: the child must be confined with its parent.
SPIN = "import os, time\nos.fork()\nend = time.monotonic() + 30\nwhile time.monotonic() < end: pass"


def test_a_quota_under_a_tenth_of_a_core_lengthens_the_period_not_below_a_millisecond():
    assert period_and_quota(25) == (10_000, 2_500)
    assert period_and_quota(10) == (10_000, 1_000)
    assert period_and_quota(7.5) == (13_333, 1_000)
    assert period_and_quota(5) == (20_000, 1_000)


@pytest.mark.skipif(unusable_reason() is not None, reason=str(unusable_reason()))
def test_a_process_tree_in_a_ten_percent_quota_gets_a_tenth_of_a_core_and_is_released():
    quota = CpuQuota(10, tag="test_quota")
    spinning: list[int] = []
    dirs = list(quota.dirs)
    assert dirs[0].parent == CPU_ROOT and dirs[0].is_dir()
    spin = subprocess.Popen([sys.executable, "-c", SPIN], preexec_fn=quota.join)
    try:
        time.sleep(1.0)  # interpreter start-up, then the fork
        start, wall = quota.used_s(), time.monotonic()
        spinning = quota.pids()
        assert len(spinning) == 2  # the parent and the child it forked afterwards
        time.sleep(2.0)
        share = (quota.used_s() - start) / (time.monotonic() - wall)
        periods, throttled, _stopped_s = quota.throttled()
    finally:
        quota.close()  # with both still spinning: they are moved out, then it is removed
        spin.kill()
        spin.wait()
        for pid in set(spinning) - {spin.pid}:
            os.kill(pid, signal.SIGKILL)  # the forked child, by its own pid
    # Two spinning processes would take up to two cores; together they got a tenth of one
    # (less when other jobs hold the machine's cores).
    assert 0.0 < share < 0.13, share
    assert periods > 0 and throttled > 0
    assert not any(path.exists() for path in dirs)
    quota.close()  # twice is harmless
