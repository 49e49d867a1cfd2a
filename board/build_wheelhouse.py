"""Build the wheelhouse an ARM board installs the on-board program from, with no compiler.

    python3 -m uv run python board/build_wheelhouse.py [--out ~/wheelhouse]

Everything the on-board install needs (the project without its ``ground`` extra, pinned by
uv.lock) as wheels for aarch64, CPython 3.11, manylinux_2_28 or older (Debian bookworm and
Raspberry Pi OS bookworm have glibc 2.36):
- every locked dependency, downloaded as a binary wheel for that platform;
- iceoryx2, which publishes no Linux aarch64 wheel: its sdist (the locked version) is
  cross-compiled here with maturin and zig (``--zig`` links against an old glibc), in a
  throwaway venv under ``--work`` with the Rust target ``aarch64-unknown-linux-gnu``;
- the project's own wheel.
The folder is then copied to the board and installed there with
``pip install --no-index --find-links WHEELHOUSE companion``. It prints how long each step
took and the wheelhouse's size per package. Nothing it makes goes into the repository.
"""

from __future__ import annotations

import argparse
import logging
import os
import subprocess
import sys
import tarfile
import time
from pathlib import Path

from packaging.markers import Marker
from packaging.requirements import Requirement
from packaging.tags import Tag, compatible_tags, cpython_tags
from packaging.utils import canonicalize_name, parse_wheel_filename

REPO = Path(__file__).resolve().parents[1]
# `uv run` names its own binary; otherwise the one on PATH.
UV = os.environ.get("UV", "uv")
log = logging.getLogger("build_wheelhouse")

PYTHON = (3, 11)
PY = f"{PYTHON[0]}.{PYTHON[1]}"
CP = f"cp{PYTHON[0]}{PYTHON[1]}"
ARCH = "aarch64"
RUST_TARGET = "aarch64-unknown-linux-gnu"
# Bookworm's glibc is 2.36; 2.28 is the newest policy maturin's zig link and most
# projects' aarch64 wheels meet, and everything older loads too.
NEWEST_GLIBC = (2, 28)
# Built here from source: no Linux aarch64 wheel exists on PyPI (0.10.0).
BUILT_FROM_SDIST = ("iceoryx2",)
# Markers are judged for the board, not for the machine that builds.
BOARD_MARKERS = {
    "implementation_name": "cpython",
    "platform_python_implementation": "CPython",
    "platform_machine": ARCH,
    "platform_system": "Linux",
    "sys_platform": "linux",
    "os_name": "posix",
    "python_version": PY,
    "python_full_version": f"{PY}.2",  # bookworm's 3.11.2
    "extra": "",
}


def board_platforms() -> list[str]:
    """The platform tags the board's pip accepts, newest first (manylinux_2_28 .. 2_17)."""
    major, newest = NEWEST_GLIBC
    tags = [f"manylinux_{major}_{minor}_{ARCH}" for minor in range(newest, 16, -1)]
    return [*tags, f"manylinux2014_{ARCH}"]


def board_tags() -> set[Tag]:
    """Every wheel tag CPython 3.11 on the board can install."""
    platforms = board_platforms()
    tags = set(cpython_tags(PYTHON, platforms=platforms))
    return tags | set(compatible_tags(PYTHON, CP, platforms=platforms))


def wheel_fits_board(filename: str) -> bool:
    """Whether a wheel file (by its name) installs on the board."""
    _, _, _, tags = parse_wheel_filename(filename)
    return not tags.isdisjoint(board_tags())


def board_requirements(exported: str) -> tuple[list[str], list[str]]:
    """From ``uv export``'s requirements: the pins to download for the board, and those to
    build from their sdist. Lines whose markers do not hold on the board are left out."""
    download, build = [], []
    for line in exported.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line or line.startswith("-"):
            continue
        req = Requirement(line)
        if req.marker is not None and not Marker(str(req.marker)).evaluate(BOARD_MARKERS):
            continue
        pin = f"{req.name}{req.specifier}"
        built = canonicalize_name(req.name) in BUILT_FROM_SDIST
        (build if built else download).append(pin)
    return download, build


def download_command(pip: list[str], requirements: Path, dest: Path) -> list[str]:
    """pip download of binary wheels for the board's platform, dependencies already pinned."""
    platforms = [arg for p in board_platforms() for arg in ("--platform", p)]
    return [*pip, "download", "--only-binary=:all:", "--no-deps", *platforms,
            "--python-version", PY, "--implementation", "cp",
            "--abi", CP, "-r", str(requirements), "-d", str(dest)]  # fmt: skip


def maturin_command(maturin: Path, dest: Path) -> list[str]:
    """maturin's release build of a pyo3 project for the board, linked by zig."""
    return [str(maturin), "build", "--release", "--target", RUST_TARGET, "--zig",
            "--compatibility", "manylinux_{}_{}".format(*NEWEST_GLIBC),
            "-i", f"python{PY}", "-o", str(dest)]  # fmt: skip


def sizes_per_package(wheelhouse: Path) -> list[tuple[str, int]]:
    """Each package's wheels in the folder and their bytes, largest first."""
    sizes: dict[str, int] = {}
    for wheel in wheelhouse.glob("*.whl"):
        name = str(parse_wheel_filename(wheel.name)[0])
        sizes[name] = sizes.get(name, 0) + wheel.stat().st_size
    return sorted(sizes.items(), key=lambda item: -item[1])


def run(cmd: list[str], **kwargs: object) -> None:
    log.info("$ %s", " ".join(cmd))
    subprocess.run(cmd, check=True, **kwargs)  # type: ignore[call-overload]


def tools_venv(work: Path) -> Path:
    """A throwaway venv outside the repository with pip, maturin and zig."""
    venv = work / "tools"
    if not (venv / "bin" / "maturin").exists():
        run([sys.executable, "-m", "venv", str(venv)])
        run([str(venv / "bin" / "pip"), "install", "-q", "maturin>=1.8,<2", "ziglang"])
    return venv


def build_from_sdist(pin: str, venv: Path, work: Path, dest: Path) -> None:
    """Download a package's sdist and cross-compile its wheel for the board."""
    bin_dir = venv / "bin"
    # maturin (the sdist's build backend) must be on PATH for pip to read its metadata, and
    # zig is found as `python3 -m ziglang` of the venv's own interpreter.
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}"}
    sdists = work / "sdist"
    name = Requirement(pin).name
    run([str(bin_dir / "pip"), "download", "-q", "--no-deps", f"--no-binary={name}",
         "--no-build-isolation", pin, "-d", str(sdists)], env=env)  # fmt: skip
    version = str(Requirement(pin).specifier).lstrip("=")
    sdist = next(sdists.glob(f"{name}-{version}.tar.gz"))
    with tarfile.open(sdist) as tar:
        tar.extractall(work / "src", filter="data")
    run(["rustup", "target", "add", RUST_TARGET])
    # The machine is shared: the compile yields to everyone else's work.
    cmd = ["nice", "-n", "10", *maturin_command(bin_dir / "maturin", dest)]
    run(cmd, cwd=work / "src" / sdist.name.removesuffix(".tar.gz"), env=env)


def build(out: Path, work: Path) -> dict[str, float]:
    """Fill the wheelhouse; the seconds each step took."""
    times: dict[str, float] = {}
    out.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()
    exported = subprocess.run(
        [UV, "export", "--frozen", "--no-dev", "--no-hashes",
         "--no-emit-project", "--no-header", "--no-annotate"],
        cwd=REPO, capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    download, built = board_requirements(exported)
    requirements = work / "board-requirements.txt"
    requirements.write_text("\n".join(download) + "\n")
    venv = tools_venv(work)
    run(download_command([str(venv / "bin" / "pip")], requirements, out))
    times["download"], started = time.monotonic() - started, time.monotonic()
    for pin in built:
        build_from_sdist(pin, venv, work, out)
    times["iceoryx2 build"], started = time.monotonic() - started, time.monotonic()
    run([UV, "build", "-q", "--wheel", "-o", str(out)], cwd=REPO)
    times["project wheel"] = time.monotonic() - started
    return times


def report(out: Path, times: dict[str, float]) -> None:
    """Print the steps' times and the wheelhouse per package; fail on a wheel that the
    board could not install."""
    for step, seconds in times.items():
        print(f"{step:16} {seconds:7.0f} s")
    sizes = sizes_per_package(out)
    total = sum(size for _, size in sizes)
    print(f"wheelhouse {out}: {total / 1e6:.1f} MB in {len(sizes)} packages")
    for name, size in sizes:
        print(f"  {size / 1e6:7.2f} MB  {name}")
    unfit = [w.name for w in out.glob("*.whl") if not wheel_fits_board(w.name)]
    if unfit:
        sys.exit(f"wheels the board cannot install: {unfit}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path.home() / "wheelhouse",
                    help="where the wheels go (default ~/wheelhouse)")  # fmt: skip
    ap.add_argument("--work", type=Path, default=Path.home() / ".cache" / "companion-arm64",
                    help="the throwaway venv, sdists and the Rust build "
                         "(default ~/.cache/companion-arm64)")  # fmt: skip
    ap.add_argument("--report-only", action="store_true", help="print an existing wheelhouse")
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    times = {} if args.report_only else build(args.out.resolve(), args.work.resolve())
    report(args.out, times)


if __name__ == "__main__":
    main()
