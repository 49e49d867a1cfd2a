"""The entry point of a plug-in process: forked by the fork server, or started as
``python -m companion.exec_control.host_main SPEC_JSON`` when there is none. The spec
names one plug-in (``plugin_host``) or several composed into this process
(``composed_host``, a config's ``process = "NAME"``)."""

from __future__ import annotations

import json
import sys

from companion.exec_control import composed_host, plugin_host


def main(argv: list[str] | None = None) -> int:
    """Run the plug-in(s) of argv[0], the JSON spec from the supervisor; the exit status."""
    args = sys.argv[1:] if argv is None else argv
    spec = json.loads(args[0])
    if "members" in spec:
        return composed_host.main(spec)
    return plugin_host.main(spec)


if __name__ == "__main__":
    sys.exit(main())
