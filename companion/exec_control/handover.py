"""The command line hands its process over to the long-running vehicle program.

The ``companion`` command parses its options with typer, which brings rich and pydantic
with it: ~19 MB of a vehicle's memory (PSS, measured with ``benchmarks/footprint.py``)
once the fork server and every plug-in have inherited those pages and written to them.
None of it is used after the options are parsed. So, once a command has checked what it
was asked, it replaces its own image with ``python -m MODULE`` (``os.execv``: the same
process id, so a service manager's signals and a test's ``kill`` still reach the
vehicle) and passes what it parsed along in a memory file.

The payload is pickled: the parsed options are this program's own dataclasses, written by
this process for the image that replaces it, never read from outside.
"""

from __future__ import annotations

import logging
import os
import pickle
import sys
from typing import Any, NoReturn

PAYLOAD_FLAG = "--handover-fd"


def exec_module(module: str, payload: Any) -> NoReturn:
    """Become ``python -m module``, which reads ``payload`` back with ``received``.

    The original command line follows on the new one, so that ``ps`` still says what the
    process is.
    """
    fd = os.memfd_create("companion-handover", 0)
    os.write(fd, pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL))
    os.lseek(fd, 0, os.SEEK_SET)
    os.set_inheritable(fd, True)
    logging.shutdown()  # flushes every handler
    sys.stdout.flush()
    sys.stderr.flush()
    argv = [sys.executable, "-m", module, PAYLOAD_FLAG, str(fd), "--", *sys.argv]
    os.execv(sys.executable, argv)


def received(argv: list[str]) -> Any:
    """The payload handed over by ``exec_module`` (argv: the new process's arguments)."""
    if len(argv) < 2 or argv[0] != PAYLOAD_FLAG:
        raise SystemExit(f"started by the companion command only ({PAYLOAD_FLAG} FD missing)")
    with os.fdopen(int(argv[1]), "rb") as f:
        return pickle.load(f)
