"""Vehicle configs the runtime tests run (test plug-ins named by module:Class)."""

PIPELINE = """
[vehicle]
name = "pipeline"

[[plugins]]
name = "imu"
plugin = "tests.support.plugins:Ticker"
settings = { rate_hz = 50.0 }

[[plugins]]
name = "relay"
plugin = "tests.support.plugins:Relay"
group = "{relay_group}"

[[plugins]]
name = "idle"
plugin = "tests.support.plugins:Waiting"
"""


def pipeline(relay_group: str = "core") -> str:
    """IMU ticker → relay → nav/state, plus a plug-in that only waits."""
    return PIPELINE.replace("{relay_group}", relay_group)
