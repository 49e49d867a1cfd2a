"""Bus namespaces: each vehicle (and each test) gets its own iceoryx2 resource prefix.

Naming and checking a namespace needs no iceoryx2 (the command line does it before the
vehicle's process imports anything heavy): only the functions that reach the shared
memory import it.

Channels of one namespace are invisible to every other one, so two vehicles, or two
tests running at once, never collide. The namespace comes from the vehicle config or
the ``COMPANION_BUS`` environment variable (default ``companion``).
"""

from __future__ import annotations

import logging
import os
import re
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import iceoryx2 as iox2

log = logging.getLogger(__name__)

ENV_VAR = "COMPANION_BUS"
DEFAULT_NAMESPACE = "companion"
_VALID = re.compile(r"^[A-Za-z0-9_.-]{1,40}$")
SHM_DIR = Path("/dev/shm")
# iceoryx2's own files (each service's and node's static description, the event sockets):
# on tmpfs, not in /tmp. iceoryx2 fsyncs every one it writes (14 per channel a process
# opens), and /tmp is often on the board's disk or SD card: each plug-in's start spent
# 0.2-0.3 s there (8 channels: 0.23 s under /tmp on this machine's disk, 0.02 s here), on
# the path of a vehicle restarted in the air. Each namespace has its own folder for them
# (``iox_dir``), removed whole with its shared memory, so nothing of a vehicle stays in
# /dev/shm once it has stopped (a reboot clears them anyway).
# Per reader, room for publishers gone (a plug-in restarted) while their samples were still
# unread. Each place costs every reader 3.5 KB of its process's own memory: iceoryx2's
# default of 128 took ~0.5 MB a reader, a quarter of the vehicle's, and 16 took 98 KB
# where 8 take 70 (3 MB over a vehicle's hundred readers). A reader reads at least once
# a second, and the supervisor's back-off restarts a process at most four times in one;
# a composed process that died twice between two reads would leave its three writers of
# link/commands six places, and only a crash loop fills eight, whose unread samples
# lost are the oldest of a dead publisher's.
EXPIRED_CONNECTIONS = 8

_log_level_set = False


def quiet_iceoryx() -> None:
    """Keep iceoryx2's own console logging to errors (once per process)."""
    import iceoryx2 as iox2

    global _log_level_set
    if not _log_level_set:
        iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
        _log_level_set = True


def default_namespace() -> str:
    """The namespace from the environment, or the default one."""
    return os.environ.get(ENV_VAR, DEFAULT_NAMESPACE)


def validate_namespace(namespace: str) -> str:
    """Return the namespace if usable as a file-name prefix, else raise ValueError."""
    if not _VALID.match(namespace):
        raise ValueError(
            f"bus namespace {namespace!r} must be 1-40 characters of letters, digits, '_', '-', '.'"
        )
    return namespace


def prefix_of(namespace: str) -> str:
    """The iceoryx2 resource prefix of a namespace."""
    return f"cmp_{validate_namespace(namespace)}_"


def iox_dir(namespace: str) -> Path:
    """The folder of iceoryx2's own files for this namespace (a name with its prefix)."""
    return SHM_DIR / f"{prefix_of(namespace)}iox"


def make_config(namespace: str) -> iox2.config.Config:
    """An iceoryx2 config whose every resource carries the namespace's prefix."""
    import iceoryx2 as iox2

    quiet_iceoryx()
    cfg = iox2.config.global_config()
    cfg.global_cfg.prefix = iox2.FileName.new(prefix_of(namespace))
    cfg.global_cfg.root_path = iox2.Path.new(f"{iox_dir(namespace)}/")
    cfg.defaults.publish_subscribe.subscriber_expired_connection_buffer = EXPIRED_CONNECTIONS
    return cfg


def alive_nodes(namespace: str) -> int:
    """How many iceoryx2 nodes of this namespace belong to living processes."""
    import iceoryx2 as iox2

    cfg = make_config(namespace)
    states = iox2.Node.list(iox2.ServiceType.Ipc, cfg)
    return sum(1 for s in states if isinstance(s, iox2.NodeState.Alive))


# The vehicle supervisor's bus node is named after this (``SUPERVISOR_NODE.PID``), which is
# how ``running_supervisor`` tells it from any other process on the bus.
SUPERVISOR_NODE = "exec_control"


def running_supervisor(namespace: str) -> int | None:
    """The pid of a living vehicle supervisor on this namespace's bus; None when there is
    none."""
    import iceoryx2 as iox2

    for state in iox2.Node.list(iox2.ServiceType.Ipc, make_config(namespace)):
        if not isinstance(state, iox2.NodeState.Alive):
            continue
        details = state[0].details
        if details is not None and details.name.as_str().split(".")[0] == SUPERVISOR_NODE:
            return int(details.process_id)
    return None


def in_use_refusal(namespace: str) -> str | None:
    """Why a vehicle may not start on this namespace's bus: another vehicle runs on it
    (two would read each other's sensors and commands, and share their devices' bytes);
    None when it is free."""
    pid = running_supervisor(namespace)
    if pid is None:
        return None
    return (
        f"bus namespace {namespace!r} is in use by the vehicle of process {pid}: stop it "
        "first, or start this one on another namespace (--namespace NAME, or namespace in "
        "the config's [vehicle] table)"
    )


def cleanup_namespace(namespace: str) -> int:
    """Remove what dead processes of this namespace left behind; return files removed.

    While other nodes live, the dead ones (a plug-in killed with SIGKILL) are cleaned
    through iceoryx2 itself, read from one listing of the namespace's nodes. When none is
    alive any more, the namespace's prefixed files (the dead nodes', the global management
    segment iceoryx2 keeps, any orphaned segment) are deleted, so nothing is left in
    /dev/shm.
    """
    import iceoryx2 as iox2

    states = iox2.Node.list(iox2.ServiceType.Ipc, make_config(namespace))
    if any(isinstance(state, iox2.NodeState.Alive) for state in states):
        # Others still use the bus: only the dead nodes go, each through iceoryx2. With
        # none alive the files are simply removed, which is quicker (the 13 nodes of a
        # vehicle killed whole: 92 ms through iceoryx2 on an idle machine).
        _remove_dead(states)
        return 0
    return _remove_prefixed_files(prefix_of(namespace))


def cleanup_dead_nodes(namespace: str) -> int:
    """Remove the ports and files of this namespace's dead iceoryx2 nodes (processes killed
    with SIGKILL) from every service they were in; how many nodes were removed."""
    import iceoryx2 as iox2

    try:
        states = iox2.Node.list(iox2.ServiceType.Ipc, make_config(namespace))
    except Exception as exc:  # a namespace being removed by another process meanwhile
        log.debug("iceoryx2 node list: %s", exc)
        return 0
    return _remove_dead(states)


def _remove_dead(states: list[Any]) -> int:
    """Remove the stale resources of the dead nodes among ``states`` (``Node.list``'s);
    how many were removed."""
    import iceoryx2 as iox2

    removed = 0
    for state in states:
        if not isinstance(state, iox2.NodeState.Dead):
            continue
        try:
            state[0].try_remove_stale_resources()
            removed += 1
        except Exception as exc:  # a half-written node of a process killed mid-start
            log.debug("iceoryx2 dead-node cleanup: %s", exc)
    return removed


def _matching(base: Path, prefix: str) -> list[Path]:
    """This namespace's paths under ``base``. Other namespaces' files come and go while the
    directory is walked (other vehicles and tests clean up at the same time): a walk that
    trips over one is started again."""
    for _ in range(5):
        try:
            return list(base.glob(f"{prefix}*"))
        except FileNotFoundError:
            continue
    return []


def _remove_prefixed_files(prefix: str) -> int:
    """Remove this namespace's shared memory and its iceoryx2 folder (``iox_dir``), which
    holds its nodes' and services' descriptions."""
    removed = 0
    if not SHM_DIR.exists():
        return 0
    for path in _matching(SHM_DIR, prefix):
        try:
            if path.is_dir():
                shutil.rmtree(path)
            else:
                path.unlink()
            removed += 1
        except FileNotFoundError:
            pass  # inside a folder removed a moment ago
        except OSError as exc:
            log.warning("cannot remove %s: %s", path, exc)
    return removed


def leftover_files(namespace: str) -> list[Path]:
    """Files of this namespace still present in /dev/shm (for tests and diagnostics)."""
    prefix = prefix_of(namespace)
    if not SHM_DIR.exists():
        return []
    return sorted(SHM_DIR.glob(f"{prefix}*"))
