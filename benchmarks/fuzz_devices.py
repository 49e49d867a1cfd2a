"""The serial sensor plug-ins under hostile streams on their ptys, with counts.

    uv run python benchmarks/fuzz_devices.py [--seconds 60]

A vehicle runs the NMEA GPS, OS-3000 compass and VectorNav IMU plug-ins on three
pseudo-terminals; each gets a seeded hostile stream (tests/support/hostile_sentences.py:
random bytes, one-character changes, cut sentences, correct checksums around nan, inf,
huge or empty fields, and valid sentences between them). Printed per device: pieces
written (and how many were valid), frames the plug-in accepted and rejected, samples it
published, and its restarts (must be 0).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.fuzz.test_hostile_devices import DEVICES, sensors_vehicle  # noqa: E402
from tests.support.hostile_sentences import hostile_stream  # noqa: E402
from tests.support.pty import Pty  # noqa: E402
from tests.support.vehicle import Vehicle  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=60.0)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="fuzz_devices"))
    ptys = {name: Pty(tmp / f"tty_{name}") for name in DEVICES}
    vehicle = Vehicle(sensors_vehicle(ptys), tmp, None).start()
    try:
        for name in DEVICES:
            vehicle.wait_running(name, 60)
        streams = {n: hostile_stream(d[1], seed=i) for i, (n, d) in enumerate(DEVICES.items())}
        written, valid = Counter(), Counter()
        samples = Counter()
        readers = {ch: vehicle.bus.queue_reader(ch) for n, d in DEVICES.items() for ch in d[2]}
        end = time.monotonic() + args.seconds
        while time.monotonic() < end:
            for name, stream in streams.items():
                text, ok = stream()
                ptys[name].write(text)
                written[name] += 1
                valid[name] += ok
            for channel, reader in readers.items():
                samples[channel] += sum(1 for _ in reader.drain())
            time.sleep(0.002)
        time.sleep(2.0)  # the health table catches up
        for name in DEVICES:
            row = vehicle.row(name)
            print(f"{name:<8} {written[name]:>7} pieces ({valid[name]} valid): "
                  f"{row.frames_ok} accepted, {row.frames_bad} rejected, "
                  f"restarts {row.restarts}")  # fmt: skip
        print("published:", ", ".join(f"{c} {n}" for c, n in samples.items()))
    finally:
        vehicle.close()


if __name__ == "__main__":
    main()
