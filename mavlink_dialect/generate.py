"""Regenerate ``companion.py`` from ``companion.xml`` with pymavlink's mavgen.

Usage: ``uv run python -m mavlink_dialect.generate [OUTPUT.py]``
"""

from __future__ import annotations

import sys
from pathlib import Path

from pymavlink.generator import mavgen

HERE = Path(__file__).resolve().parent
XML = HERE / "companion.xml"


def generate(output: Path) -> None:
    """Run mavgen (Python 3, MAVLink 2) on companion.xml, writing ``output``."""
    opts = mavgen.Opts(
        str(output.with_suffix("")), wire_protocol="2.0", language="Python3", validate=True
    )
    if not mavgen.mavgen(opts, [str(XML)]):
        raise RuntimeError(f"mavgen failed on {XML}")


if __name__ == "__main__":
    generate(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "companion.py")
