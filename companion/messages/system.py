"""The execution control's view: per-plug-in counters, the health table, parameter changes."""

from __future__ import annotations

import ctypes
import enum

from companion.messages.base import MAX_PLUGINS, NAME_LEN, Message


class PluginState(enum.IntEnum):
    """Life-cycle state of a plug-in as the execution control sees it."""

    STOPPED = 0
    STARTING = 1
    RUNNING = 2
    BACKOFF = 3  # died; waiting before the next restart
    FAILED = 4  # gave up (too many restarts in a row)


class PluginStats(Message):
    """A plug-in's own counters, published about once a second by its runner.

    Producers: every plug-in process. Consumers: exec_control (merged into system/health).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("name", ctypes.c_char * NAME_LEN),
        ("pid", ctypes.c_int32),
        ("steps", ctypes.c_uint64),
        ("frames_ok", ctypes.c_uint64),
        ("frames_bad", ctypes.c_uint64),  # checksum failures and garbage
        ("dropped", ctypes.c_uint64),  # samples lost on queue overflow
        ("refused", ctypes.c_uint64),  # well-formed input refused by its rules
        ("bytes_in", ctypes.c_uint64),  # read from the plug-in's device
        ("step_p50_us", ctypes.c_double),
        ("step_p99_us", ctypes.c_double),
        # Of a plug-in sharing its process with others (``process`` in the config), whose
        # host restarts it alone: its restarts there, its state, and its thread's CPU share.
        ("restarts", ctypes.c_uint32),
        ("state", ctypes.c_uint8),  # PluginState; 0 from a process of its own
        ("cpu_pct", ctypes.c_double),
    ]


class PluginHealth(Message):
    """One row of the health table."""

    _fields_ = [
        ("name", ctypes.c_char * NAME_LEN),
        ("kind", ctypes.c_char * 48),  # the plug-in named in the config
        ("group", ctypes.c_char * 8),  # "core" or "flight"
        ("state", ctypes.c_uint8),  # PluginState
        ("pid", ctypes.c_int32),
        ("restarts", ctypes.c_uint32),
        ("cpu_pct", ctypes.c_double),  # share of one core over the last second
        ("rss_kib", ctypes.c_uint32),
        ("frames_ok", ctypes.c_uint64),
        ("frames_bad", ctypes.c_uint64),
        ("dropped", ctypes.c_uint64),
        ("refused", ctypes.c_uint64),
        ("bytes_in", ctypes.c_uint64),  # read from its device: silence told from garbage
        ("step_p50_us", ctypes.c_double),
        ("step_p99_us", ctypes.c_double),
        ("process", ctypes.c_char * NAME_LEN),  # the OS process it shares ("": its own)
        # The plug-in's own time of the counters above (0: none yet). A device's silence is
        # judged over this time, not the table's: a plug-in reports once a wall second, so
        # two tables of a lockstep simulation running 10x may carry the same counters.
        ("counted_us", ctypes.c_int64),
    ]


class SystemHealth(Message):
    """The execution control's table of every plug-in. Producer: exec_control.

    Consumers: `companion status`, link (plug-in health, SYS_STATUS).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("supervisor_pid", ctypes.c_int32),
        ("flight_running", ctypes.c_uint8),  # the flight group is started (armed)
        ("count", ctypes.c_uint8),
        ("plugins", PluginHealth * MAX_PLUGINS),
    ]

    def rows(self) -> list[PluginHealth]:
        """The filled rows of the table."""
        return [self.plugins[i] for i in range(self.count)]

    def row_of_kind(self, kind: bytes) -> PluginHealth | None:
        """The first row of a plug-in of this kind (``b"actuators.minissc"``); None: none."""
        return next((r for r in self.rows() if r.kind == kind), None)


class ParamChange(Message):
    """A parameter a ground station set. Producer: link. Consumers: the parameter's owner."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("value", ctypes.c_double),
        ("name", ctypes.c_char * 17),
    ]


class LogProgress(Message):
    """How far the flight log has written. Producer: ``system.logger`` with ``in_step``.
    Consumer: the simulator bridge, whose exact lockstep waits for it (no sample lost)."""

    _fields_ = [
        ("t_us", ctypes.c_int64),  # the newest IMU sample written (all before it drained)
    ]
