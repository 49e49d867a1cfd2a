"""The fork server: one pre-imported Python process that forks the plug-in processes.

A fresh interpreter per plug-in imports numpy, pymavlink, iceoryx2 and the project's
libraries again, each copy private: ten processes of ~25-90 MB. The fork server
(``python -m companion.exec_control.zygote``) imports them once, with every plug-in class
of the config, and forks a process per plug-in on request; the children share those pages
copy-on-write. It opens no bus node, device or port: each plug-in opens its own after the
fork, in its own process, exactly as a spawned one would.

Every plug-in is forked twice (fork server -> short-lived middle -> plug-in) so that, when
the middle exits at once, the kernel hands the plug-in to the supervisor (a child
sub-reaper): the supervisor is its parent as before, reaps it, sees its exit status and is
told by SIGCHLD when it dies; a dead fork server takes no plug-in with it.

The first fork server is forked from the supervisor itself, before it has a thread or a
bus node, so that what the supervisor imported is shared too; one started later (after
the first died) is a fresh interpreter.

Protocol: the supervisor writes one JSON spec per line on the request pipe; the fork
server answers the new plug-in's pid on the reply pipe (``ready`` first, once its imports
are done). End of input: the fork server exits.
"""

from __future__ import annotations

import ctypes
import gc
import json
import logging
import os
import select
import signal
import subprocess
import sys
import time
from typing import IO

log = logging.getLogger(__name__)

PRELOAD = (
    "numpy",
    "iceoryx2",
    "mavlink_dialect.companion",
    "companion.bus.node",
    "companion.bus.clock",
    "companion.messages",
    "companion.exec_control.host_main",
)
READY_TIMEOUT_S = 20.0  # a first start on a busy machine (imports from a cold disk)
REPLY_TIMEOUT_S = 2.0
REPARENT_TIMEOUT_S = 2.0
_PR_SET_CHILD_SUBREAPER = 36
# The vehicle's matrices are tiny: one BLAS thread, and no thread alive at fork time.
CHILD_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def become_subreaper() -> bool:
    """Adopt the orphans of this process's descendants (the forked plug-ins); Linux only."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


class ForkedProcess:
    """A plug-in process forked by the fork server and adopted by this one (Popen-like)."""

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            try:
                pid, status = os.waitpid(self.pid, os.WNOHANG)
            except ChildProcessError:  # not adopted after all: nothing to reap
                self.returncode = -signal.SIGKILL if _gone(self.pid) else None
                return self.returncode
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.poll() is None:
            if deadline is not None and time.monotonic() >= deadline:
                raise subprocess.TimeoutExpired(f"pid {self.pid}", timeout or 0.0)
            time.sleep(0.005)
        assert self.returncode is not None
        return self.returncode

    def send_signal(self, sig: int) -> None:
        if self.poll() is None:
            try:
                os.kill(self.pid, sig)
            except ProcessLookupError:
                pass

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


class ForkServer:
    """The supervisor's handle on its fork server: start it, ask it for plug-ins, stop it."""

    def __init__(self, kinds: list[str], log_level: str) -> None:
        self.kinds, self.log_level = kinds, log_level
        self.proc: subprocess.Popen[bytes] | ForkedProcess | None = None
        self._replies: IO[bytes] | None = None
        self._requests: IO[bytes] | None = None
        self.ready = False
        self.starts = 0

    def start(self) -> None:
        """Start the fork server (it imports in the background; see ``wait_ready``)."""
        read_fd, write_fd = os.pipe()
        request_fd, feed_fd = os.pipe()
        if self.starts == 0 and _threads() == 1:
            # The supervisor imports the plug-ins' modules itself (their pre-arm checks,
            # the simulation's session): imported once here, before the fork, they are one
            # copy shared with the fork server and every plug-in, not two. The collector
            # must then not walk (and so copy) the pages now shared.
            _preload(self.kinds)
            pid = os.fork()
            if pid == 0:
                os.close(read_fd)
                os.close(feed_fd)
                _forked_server(self.kinds, request_fd, write_fd)
            self.proc, how = ForkedProcess(pid), "forked"
        else:
            fds = {"request_fd": request_fd, "reply_fd": write_fd}
            arg = json.dumps({"kinds": self.kinds, "log_level": self.log_level, **fds})
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "companion.exec_control.zygote", arg],
                stdin=subprocess.DEVNULL,
                pass_fds=(request_fd, write_fd),
                env={**os.environ, **CHILD_ENV},
                start_new_session=True,
            )
            how = "spawned"
        os.close(write_fd)
        os.close(request_fd)
        self._replies, self._requests = os.fdopen(read_fd, "rb"), os.fdopen(feed_fd, "wb")
        self.ready = False
        self.starts += 1
        log.info("fork server %s, pid %d", how, self.proc.pid)

    def alive(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    def wait_ready(self, timeout_s: float) -> bool:
        """True once the fork server has done its imports (waiting at most ``timeout_s``)."""
        if not self.ready and self.alive():
            self.ready = self._read_line(timeout_s) == b"ready"
        return self.ready

    def spawn(self, spec_json: str) -> ForkedProcess | None:
        """A forked plug-in process, or None if the fork server cannot give one now."""
        if not self.alive() or not self.wait_ready(0.0):
            return None
        assert self._requests is not None
        try:
            self._requests.write(spec_json.encode() + b"\n")
            self._requests.flush()
            pid = int(self._read_line(REPLY_TIMEOUT_S) or b"0")
        except (OSError, ValueError):
            pid = 0
        if pid <= 0:
            log.warning("fork server gave no process: stopping it, spawning meanwhile")
            self.stop()
            return None
        return ForkedProcess(pid)

    def _read_line(self, timeout_s: float) -> bytes:
        assert self._replies is not None
        ready, _, _ = select.select([self._replies], [], [], timeout_s)
        return self._replies.readline().strip() if ready else b""

    def reap(self) -> bool:
        """True when the fork server has died since it was started (and forget it)."""
        if self.proc is None or self.proc.poll() is None:
            return False
        log.warning("fork server died (status %s)", self.proc.returncode)
        self._forget()
        return True

    def stop(self) -> None:
        """End of input: the fork server exits; killed if it does not within a second."""
        if self.proc is None:
            return
        try:
            if self._requests is not None:
                self._requests.close()
            self.proc.wait(1.0)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()
            self.proc.wait()
        self._forget()

    def _forget(self) -> None:
        for pipe in (self._replies, self._requests):
            if pipe is not None:
                try:
                    pipe.close()
                except OSError:
                    pass  # a request half-written to a dead fork server
        self.proc, self._replies, self._requests, self.ready = None, None, None, False


# --- the fork server process ---------------------------------------------------------


def _preload(kinds: list[str]) -> None:
    import importlib

    from companion.exec_control.registry import PluginLoadError, load

    for name in PRELOAD:
        importlib.import_module(name)
    for kind in kinds:
        try:
            load(kind)
        except PluginLoadError as exc:  # the plug-in's own process reports it properly
            log.debug("not preloaded: %s", exc)
    # Objects that exist now are never freed: keep the collector off their pages, which
    # then stay shared with the children. No collection first: the cycles it would free
    # leave holes in those pages, and a child's first allocations fill the holes, copying
    # each page (measured: ~3 MB of private pages over a flying vehicle's 12 plug-ins).
    gc.freeze()


def _threads() -> int:
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return 1


def _run_child(spec_json: str, middle: int, supervisor: int, fds: tuple[int, ...]) -> None:
    """In the plug-in process: wait to be adopted by the supervisor, then run the plug-in."""
    code = 1
    try:
        os.setsid()  # a terminal's Ctrl-C reaches the supervisor only
        for fd in fds:
            os.close(fd)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.close(null)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        deadline = time.monotonic() + REPARENT_TIMEOUT_S
        while os.getppid() == middle and time.monotonic() < deadline:
            time.sleep(0.0002)
        logging.root.handlers.clear()
        from companion.exec_control.host_main import main
        from companion.exec_control.plugin_host import set_name

        set_name(json.loads(spec_json).get("name", "plugin"))

        if os.getppid() == supervisor:  # not adopted: the supervisor is gone, so stop
            code = main([spec_json])
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException:
        logging.getLogger("companion.plugin_host").exception("forked plug-in failed")
    finally:
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)


def _fork_plugin(spec_json: str, supervisor: int, fds: tuple[int, int]) -> int:
    """Fork a plug-in process (through a middle one that exits); its pid."""
    read_fd, write_fd = os.pipe()
    middle = os.fork()
    if middle == 0:
        try:
            # The middle's pid is taken before the fork: asked in the child, getppid() is
            # already the supervisor's when the middle has exited first, and the child
            # then waited its whole REPARENT_TIMEOUT_S (2 s) for an adoption long done.
            middle_pid = os.getpid()
            pid = os.fork()
            if pid == 0:
                _run_child(spec_json, middle_pid, supervisor, (read_fd, write_fd, *fds))
            os.write(write_fd, f"{pid}\n".encode())
        finally:
            os._exit(0)
    os.close(write_fd)
    with os.fdopen(read_fd, "rb") as pipe:
        text = pipe.readline()
    os.waitpid(middle, 0)
    return int(text or b"0")


def serve(kinds: list[str], request_fd: int, reply_fd: int) -> int:
    """Preload, say ``ready``, then fork one plug-in per spec line until end of input."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the supervisor decides when this ends
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
    supervisor = os.getppid()
    _preload(kinds)
    if _threads() > 1:  # a thread in a forked child would be a copy without its owner
        log.warning("fork server has %d threads before forking", _threads())
    os.write(reply_fd, b"ready\n")
    fds = (request_fd, reply_fd)
    with os.fdopen(request_fd, "rb") as requests:
        for line in requests:
            if spec_json := line.decode().strip():
                os.write(reply_fd, f"{_fork_plugin(spec_json, supervisor, fds)}\n".encode())
    return 0


def _forked_server(kinds: list[str], request_fd: int, reply_fd: int) -> None:
    """The fork server forked from the supervisor: serve, then leave without unwinding."""
    code = 1
    try:
        os.setsid()
        from companion.exec_control.plugin_host import die_with_parent

        die_with_parent()
        code = serve(kinds, request_fd, reply_fd)
    except BaseException:
        log.exception("fork server failed")
    finally:
        logging.shutdown()
        os._exit(code)


def main(argv: list[str] | None = None) -> int:
    args = json.loads((sys.argv[1:] if argv is None else argv)[0])
    logging.basicConfig(
        level=args.get("log_level", "INFO"),
        format="%(asctime)s fork_server[%(process)d] %(levelname)s %(message)s",
    )
    from companion.exec_control.plugin_host import die_with_parent

    die_with_parent()
    return serve(args["kinds"], args["request_fd"], args["reply_fd"])


if __name__ == "__main__":
    sys.exit(main())
