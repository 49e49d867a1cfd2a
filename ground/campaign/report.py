"""The campaign's report: distributions per airframe and condition, the worst flights'
tracks, and every flight in a table, as PNGs and one HTML page beside the results."""

from __future__ import annotations

import html
import logging
import math
from collections import defaultdict
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from companion.control.mission.plan import checked_plan
from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate
from mavlink_dialect import companion as d

log = logging.getLogger(__name__)
METRICS = (
    ("xtrack_p95_m", "cross-track p95 (m)"),
    ("alt_rms_m", "height error RMS (m)"),
    ("airspeed_rms_m_s", "airspeed error RMS (m/s)"),
)
WORST = 4
TABLE_COLUMNS = ("flight_id", "airframe", "condition", "status", "completed", "xtrack_rms_m",
                 "xtrack_p95_m", "alt_rms_m", "airspeed_rms_m_s", "time_to_complete_s",
                 "failsafes", "error")  # fmt: skip


def badness(row: dict[str, Any]) -> tuple[int, float]:
    """Sort key, worst first: failed, then not completed, then by cross-track p95."""
    p95 = row.get("xtrack_p95_m", math.nan)
    p95 = float(p95) if isinstance(p95, int | float) and not math.isnan(p95) else math.inf
    rank = 0 if row["status"] != "ok" else 1 if not row["completed"] else 2
    return (rank, -p95)


def write_report(rows: list[dict[str, Any]], out_dir: Path, name: str) -> Path:
    """Draw the figures and write ``report.html``; return its path."""
    out_dir.mkdir(parents=True, exist_ok=True)
    figures = [_distributions(rows, out_dir / "distributions.png")]
    worst = sorted(rows, key=badness)[:WORST]
    tracks = _worst_tracks(worst, out_dir / "worst_tracks.png")
    if tracks is not None:
        figures.append(tracks)
    page = out_dir / "report.html"
    page.write_text(_html(rows, name, [f.name for f in figures]))
    return page


def _distributions(rows: list[dict[str, Any]], path: Path) -> Path:
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        groups[f"{row['airframe']}\n{row['condition']}"].append(row)
    labels = sorted(groups)
    fig, axes = plt.subplots(len(METRICS), 1, figsize=(max(6, 1.6 * len(labels)), 9))
    for ax, (key, title) in zip(axes, METRICS, strict=True):
        data = [[r[key] for r in groups[g] if _finite(r.get(key))] for g in labels]
        ax.boxplot([v if v else [math.nan] for v in data], tick_labels=labels)
        ax.set_ylabel(title)
        ax.grid(alpha=0.3)
    done = [sum(1 for r in groups[g] if r["completed"]) for g in labels]
    counts = (f"{n}/{len(groups[g])}" for n, g in zip(done, labels, strict=True))
    axes[0].set_title("missions completed: " + ", ".join(counts))
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _worst_tracks(rows: list[dict[str, Any]], path: Path) -> Path | None:
    drawn = 0
    fig, ax = plt.subplots(figsize=(8, 8))
    for row in rows:
        truth = Path(row["log"]).with_name("truth.csv")
        try:
            t = read_estimate(truth)
        except (OSError, ValueError, KeyError):
            continue
        if len(t["lat"]) == 0:
            continue
        frame = LocalFrame(t["lat"][0], t["lon"][0])
        ne = [frame.ne(a, b) for a, b in zip(t["lat"], t["lon"], strict=True)]
        ax.plot([p[1] for p in ne], [p[0] for p in ne], lw=1, label=_label(row))
        _draw_plan(ax, row, frame)
        drawn += 1
    if not drawn:
        plt.close(fig)
        return None
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"the {drawn} worst flights")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _draw_plan(ax: Any, row: dict[str, Any], frame: LocalFrame) -> None:
    plan = Path(row.get("plan_path", ""))
    if not plan.is_file():
        return
    items = [i for i in checked_plan(plan)[0] if i.command == d.MAV_CMD_NAV_WAYPOINT]
    pts = [frame.ne(i.x / 1e7, i.y / 1e7) for i in items]
    ax.plot([p[1] for p in pts], [p[0] for p in pts], "k+", ms=10)


def _label(row: dict[str, Any]) -> str:
    p95 = row.get("xtrack_p95_m")
    figure = f"p95 {p95:.1f} m" if _finite(p95) else row["status"]
    return f"{row['flight_id']} ({row['condition']}; {figure})"


def _finite(value: Any) -> bool:
    return isinstance(value, int | float) and math.isfinite(value)


def _html(rows: list[dict[str, Any]], name: str, images: list[str]) -> str:
    ok = sum(1 for r in rows if r["status"] == "ok")
    completed = sum(1 for r in rows if r["completed"])
    head = (f"<h1>{html.escape(name)}</h1><p>{len(rows)} flights: {ok} flown to an end, "
            f"{completed} completed their mission, {len(rows) - ok} failed.</p>")  # fmt: skip
    figs = "".join(f'<p><img src="{html.escape(i)}"></p>' for i in images)
    cells = "".join(f"<th>{c}</th>" for c in TABLE_COLUMNS)
    body = "".join(_tr(r) for r in sorted(rows, key=badness))
    style = "td,th{padding:2px 6px;font:12px sans-serif}tr:nth-child(even){background:#eee}"
    return (f"<!doctype html><meta charset=utf-8><title>{html.escape(name)}</title>"
            f"<style>{style}</style>{head}{figs}<table><tr>{cells}</tr>{body}</table>")  # fmt: skip


def _tr(row: dict[str, Any]) -> str:
    cells = []
    for key in TABLE_COLUMNS:
        value = row.get(key, "")
        text = f"{value:.2f}" if isinstance(value, float) else str(value)
        if key == "flight_id":
            link = html.escape(str(Path(row["log"]).relative_to(Path(row["log"]).parents[2])))
            text = f'<a href="{link}">{html.escape(text)}</a>'
        else:
            text = html.escape(text)
        cells.append(f"<td>{text}</td>")
    return "<tr>" + "".join(cells) + "</tr>"
