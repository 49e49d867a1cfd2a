"""Navigator accuracy on the real flight logs of ``../shared/navlogs/`` (the real-log table
of ``nav_accuracy.py``).

Usage: uv run python benchmarks/nav_real_logs.py [--navlogs DIR] [--navigator ins_ekf]

Each log's sensors are replayed through ``companion replay``'s own code and scored with the
set's own scorer (``score.py``: the autopilot's estimate as reference, the first 10 s
skipped) beside the set's complementary-filter baseline (``cf``, from its
``baseline_scores.txt``). Columns: RMS roll, pitch, yaw (degrees), horizontal position (m),
velocity (m/s), and the longest time the heading was more than 30° off (s).
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ground.replay.single import replay_log

NAVLOGS = Path(__file__).resolve().parents[2] / "shared" / "navlogs"
METRICS = ("roll_rms", "pitch_rms", "yaw_rms", "hpos_rms", "vel_rms")
LOST_DEG = 30.0


def _scorer(navlogs: Path):  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("navlogs_score", navlogs / "score.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def baseline(navlogs: Path, mode: str = "cf") -> dict[str, list[float]]:
    """The set's own baseline figures per log."""
    rows: dict[str, list[float]] = {}
    for line in (navlogs / "baseline_scores.txt").read_text().splitlines():
        parts = line.split()
        if len(parts) > 2 and parts[0] == "SUMMARY" and parts[1].endswith(f".{mode}"):
            values = dict(p.split("=") for p in parts[2:])
            rows[parts[1].removesuffix(f".{mode}")] = [float(values[m]) for m in METRICS]
    return rows


def longest_lost_s(scorer, candidate, reference, skip: float = 10.0) -> float:  # type: ignore[no-untyped-def]
    """The longest run of reference rows with the heading more than 30° off."""
    t = reference["t"]
    keep = t >= t[0] + skip
    yaw = scorer.interp(t[keep], candidate["t"], candidate["yaw"], angle=True)
    error = np.abs(scorer.wrap180(np.degrees(yaw - reference["yaw"][keep])))
    longest, start = 0.0, None
    for ti, lost in zip(t[keep], error > LOST_DEG, strict=True):
        if lost and start is None:
            start = ti
        elif not lost and start is not None:
            longest, start = max(longest, ti - start), None
    if start is not None:
        longest = max(longest, t[keep][-1] - start)
    return longest


def score_log(navlogs: Path, name: str, navigator: str, out_dir: Path) -> list[float]:
    """Replay one log and score it: the METRICS and the longest lost-heading time."""
    scorer = _scorer(navlogs)
    out = out_dir / f"{name}.csv"
    replay_log(navlogs / "data" / f"{name}.sensors.csv", navigator, out)
    candidate = scorer.load(str(out))
    reference = scorer.load(str(navlogs / "data" / f"{name}.reference.csv"))
    res = scorer.score(candidate, reference, 10.0)
    keys = ("roll_deg", "pitch_deg", "yaw_deg", "hpos_m", "vel_mps")
    return [float(res[k][0]) for k in keys] + [longest_lost_s(scorer, candidate, reference)]


def real_log_table(navlogs: Path = NAVLOGS, navigator: str = "ins_ekf") -> list[str]:
    """The table's lines (markdown), or one line saying why there is none."""
    if not (navlogs / "data").is_dir():
        return [f"(no real logs: {navlogs}/data not found)"]
    cf = baseline(navlogs)
    lines = [
        f"| log | {navigator}: roll / pitch / yaw °, position m, velocity m/s | heading >30° off "
        "| cf: roll / pitch / yaw °, position m, velocity m/s |",
        "|---|---|---|---|",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for path in sorted((navlogs / "data").glob("*.sensors.csv")):
            name = path.name.removesuffix(".sensors.csv")
            *ours, lost = score_log(navlogs, name, navigator, Path(tmp))
            base = cf.get(name, [float("nan")] * 5)
            lines.append(f"| {name} | {_cells(ours)} | {lost:.1f} s | {_cells(base)} |")
    return lines


def _cells(v: list[float]) -> str:
    return f"{v[0]:.1f} / {v[1]:.1f} / {v[2]:.1f}, {v[3]:.1f}, {v[4]:.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--navlogs", type=Path, default=NAVLOGS)
    parser.add_argument("--navigator", default="ins_ekf")
    args = parser.parse_args()
    print("\nreal flight logs (reference: the autopilot's own estimate; first 10 s skipped)")
    print("\n".join(real_log_table(args.navlogs, args.navigator)))


if __name__ == "__main__":
    main()
