"""Fixed-wing control laws, free of bus and clock: each a step taking state, setpoint and dt.

``attitude`` (roll, pitch and yaw-damper loops), ``l1_guidance`` (lines and circles),
``tecs`` (height and speed through pitch and throttle) and ``wind`` (wind and airspeed
from GPS velocity and heading alone).
"""
