"""What an install of the on-board program puts on a board, per package.

    uv run python benchmarks/install_size.py [--extras ground] [--pip] [--top 25]

Installs the repository (``pip install .``, no extras unless ``--extras``) into a fresh
venv and prints ``du`` of its site-packages and the size of each installed distribution
(the files its ``RECORD`` lists, ``*.libs`` folders of bundled shared libraries included),
with the distribution that required it. By default uv installs it, which leaves the
bytecode uncompiled (as ``footprint.py`` measures); ``--pip`` uses the venv's own pip,
which compiles every module to ``.pyc`` on install (about 1.5x the size).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# Run by the venv's own interpreter: every distribution's size and who requires it.
SIZES = r"""
import json, re
from importlib import metadata
sizes, needed_by = {}, {}
for dist in metadata.distributions():
    name = dist.metadata["Name"].lower()
    total = 0
    for f in dist.files or ():
        path = dist.locate_file(f)
        if path.is_file():
            total += path.stat().st_size
    sizes[name] = total
    for req in dist.requires or ():
        if "extra ==" in req:
            continue
        dep = re.split(r"[\s;<>=!~\[(]", req, maxsplit=1)[0].lower().replace("_", "-")
        needed_by.setdefault(dep, []).append(name)
print(json.dumps({"sizes": sizes, "needed_by": needed_by}))
"""


def install(venv: Path, extras: str, use_pip: bool) -> None:
    """A fresh venv with the repository installed in it."""
    target = f"{REPO}[{extras}]" if extras else str(REPO)
    if use_pip:
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        cmd = [str(venv / "bin" / "pip"), "install", "-q", target]
    else:
        subprocess.run(["uv", "venv", "-q", "-p", sys.executable, str(venv)], check=True)
        cmd = ["uv", "pip", "install", "-q", "--python", str(venv / "bin" / "python"), target]
    subprocess.run(cmd, check=True, cwd=venv.parent)


def du_mb(path: Path) -> float:
    """``du -s`` of a folder, in MB."""
    out = subprocess.run(["du", "-sk", str(path)], capture_output=True, text=True, check=True)
    return int(out.stdout.split()[0]) / 1024


def report(venv: Path, top: int) -> None:
    """Print the total and the largest distributions."""
    site = next(venv.glob("lib/python*/site-packages"))
    out = subprocess.run(
        [str(venv / "bin" / "python"), "-c", SIZES], capture_output=True, text=True, check=True
    )
    found = json.loads(out.stdout)
    sizes: dict[str, int] = found["sizes"]
    needed_by: dict[str, list[str]] = found["needed_by"]
    print(f"site-packages: {du_mb(site):.0f} MB (du), {len(sizes)} distributions")
    for name, size in sorted(sizes.items(), key=lambda i: -i[1])[:top]:
        by = ", ".join(sorted(needed_by.get(name.replace("_", "-"), []))) or "-"
        print(f"  {size / 1e6:7.1f} MB  {name:<24} required by {by}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--extras", default="", help="e.g. ground")
    ap.add_argument("--pip", action="store_true", help="install with pip (compiles .pyc)")
    ap.add_argument("--top", type=int, default=25)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="install_size") as tmp:
        venv = Path(tmp) / "venv"
        install(venv, args.extras, args.pip)
        report(venv, args.top)


if __name__ == "__main__":
    main()
