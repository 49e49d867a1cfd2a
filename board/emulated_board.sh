#!/usr/bin/env bash
# An emulated Raspberry Pi on this x86_64 machine: a Debian bookworm arm64 root run by
# qemu-user, the on-board program installed in it from the wheelhouse with no compiler
# and no network. Run as root.
#
#   board/emulated_board.sh setup     # debootstrap the root, install the wheelhouse in it
#   board/emulated_board.sh run CONFIG.toml [companion run options]   # start the vehicle
#   board/emulated_board.sh exec CMD...   # run a command in the root (mounts made if needed)
#   board/emulated_board.sh stop      # stop what run started
#   board/emulated_board.sh teardown  # stop, unmount everything this script mounted
#
# ARM64_ROOT (default /work/arm64/root) and WHEELHOUSE ($HOME/wheelhouse, made by
# board/build_wheelhouse.py) say where. The vehicle is installed at /opt/companion in the
# root; its output goes to $ARM64_ROOT/var/log/companion.log. A config's device paths and
# state_dir are paths inside the root; the host reaches them under $ARM64_ROOT.
set -euo pipefail

ROOT=${ARM64_ROOT:-/work/arm64/root}
WHEELHOUSE=${WHEELHOUSE:-$HOME/wheelhouse}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
STATE=${ROOT}.state # outside the root: pid, and what this script mounted
VENV=/opt/companion

say() { echo "emulated_board: $*" >&2; }

host_tools() {
    local missing=()
    command -v debootstrap >/dev/null || missing+=(debootstrap)
    command -v qemu-aarch64-static >/dev/null || missing+=(qemu-user-static)
    command -v update-binfmts >/dev/null || missing+=(binfmt-support)
    if ((${#missing[@]})); then
        apt-get update -qq && apt-get install -y -qq "${missing[@]}"
    fi
    mkdir -p "$STATE"
    # The kernel runs arm64 programs through qemu once binfmt_misc knows it; the F flag
    # opens the interpreter now, so the root needs no copy of it.
    if [[ ! -e /proc/sys/fs/binfmt_misc/register ]]; then
        mount -t binfmt_misc binfmt_misc /proc/sys/fs/binfmt_misc
        touch "$STATE/binfmt_mounted"
    fi
    [[ -e /proc/sys/fs/binfmt_misc/qemu-aarch64 ]] || update-binfmts --enable qemu-aarch64
}

mount_root() {
    local m
    for m in proc dev dev/pts dev/shm; do
        mountpoint -q "$ROOT/$m" && continue
        case $m in
        proc) mount -t proc proc "$ROOT/proc" ;;
        dev) mount --bind /dev "$ROOT/dev" ;;
        dev/pts) mount --bind /dev/pts "$ROOT/dev/pts" ;;
        # The board's own shared memory: its bus is not the host's.
        dev/shm) mount -t tmpfs -o mode=1777,size=256m shm "$ROOT/dev/shm" ;;
        esac
    done
}

unmount_root() {
    local m
    for m in dev/shm dev/pts dev proc; do
        if mountpoint -q "$ROOT/$m"; then umount "$ROOT/$m" || umount -l "$ROOT/$m"; fi
    done
}

in_root() { chroot "$ROOT" /usr/bin/env -i PATH=$VENV/bin:/usr/bin:/bin HOME=/root "$@"; }

setup() {
    host_tools
    if [[ ! -x $ROOT/usr/bin/python3 ]]; then
        local t0=$SECONDS
        debootstrap --arch arm64 --include=python3,python3-venv,python3-pip \
            bookworm "$ROOT" "$MIRROR"
        say "debootstrap: $((SECONDS - t0)) s"
    fi
    ls "$WHEELHOUSE"/companion-*.whl >/dev/null || {
        say "no wheelhouse at $WHEELHOUSE: run board/build_wheelhouse.py"
        exit 1
    }
    rm -rf "$ROOT/opt/wheelhouse" && cp -r "$WHEELHOUSE" "$ROOT/opt/wheelhouse"
    local t0=$SECONDS
    # As on a board: pip from the wheelhouse alone, with no network (a namespace of its own)
    # and no compiler in the root.
    [[ -x $ROOT$VENV/bin/pip ]] || unshare --net chroot "$ROOT" /usr/bin/env -i PATH=/usr/bin:/bin HOME=/root /usr/bin/python3 -m venv $VENV
    unshare --net chroot "$ROOT" /usr/bin/env -i PATH=/usr/bin:/bin HOME=/root $VENV/bin/pip install -q --no-index \
        --find-links /opt/wheelhouse companion
    # The project's own wheel again, whatever its version: a rebuilt one replaces the last.
    unshare --net chroot "$ROOT" /usr/bin/env -i PATH=/usr/bin:/bin HOME=/root /bin/sh -c \
        "$VENV/bin/pip install -q --no-index --no-deps --force-reinstall /opt/wheelhouse/companion-*.whl"
    say "pip install from the wheelhouse: $((SECONDS - t0)) s"
    say "installed: $(du -sm "$ROOT$VENV" | cut -f1) MB in $VENV"
}

run_vehicle() {
    local config=$1
    shift
    [[ -s $STATE/pid ]] && kill -0 "$(cat "$STATE/pid")" 2>/dev/null && {
        say "already running: pid $(cat "$STATE/pid")"
        exit 1
    }
    host_tools
    mount_root
    mkdir -p "$ROOT/opt/board" "$ROOT/var/log"
    cp "$config" "$ROOT/opt/board/vehicle.toml"
    # chroot and env exec what follows: $! is the supervisor itself, not a subshell.
    chroot "$ROOT" /usr/bin/env -i PATH=$VENV/bin:/usr/bin:/bin HOME=/root \
        companion run --config /opt/board/vehicle.toml "$@" \
        >"$ROOT/var/log/companion.log" 2>&1 &
    echo $! >"$STATE/pid"
    say "vehicle started: pid $(cat "$STATE/pid"), log $ROOT/var/log/companion.log"
}

# Every process whose root is the emulated board's: only this script starts any there.
root_pids() {
    local p real
    real=$(readlink -f "$ROOT")
    for p in /proc/[0-9]*; do
        [[ $(readlink "$p/root" 2>/dev/null) == "$real" ]] && echo "${p#/proc/}"
    done
    return 0
}

stop_vehicle() {
    local pid
    if [[ -s $STATE/pid ]]; then
        pid=$(cat "$STATE/pid")
        # The supervisor stops its plug-ins on SIGTERM, as a service manager's stop does.
        kill -TERM "$pid" 2>/dev/null || true
        for _ in $(seq 60); do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
        rm -f "$STATE/pid"
    fi
    for pid in $(root_pids); do kill -KILL "$pid" 2>/dev/null || true; done
}

teardown() {
    stop_vehicle
    unmount_root
    if [[ -e $STATE/binfmt_mounted ]]; then
        umount /proc/sys/fs/binfmt_misc && rm -f "$STATE/binfmt_mounted"
    fi
    say "stopped and unmounted; the root stays at $ROOT (rm -rf it to start afresh)"
}

case ${1:-} in
setup) setup ;;
run) shift && run_vehicle "$@" ;;
exec)
    shift && host_tools && mount_root
    # exec: a signal to this script's pid reaches the command itself
    exec chroot "$ROOT" /usr/bin/env -i PATH=$VENV/bin:/usr/bin:/bin HOME=/root "$@"
    ;;
stop) stop_vehicle ;;
teardown) teardown ;;
*) sed -n 2,15p "$0" >&2 && exit 2 ;;
esac
