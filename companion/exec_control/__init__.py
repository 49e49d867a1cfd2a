"""The execution-control process: config, spawning, supervision, START/STOP."""
