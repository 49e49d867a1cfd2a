"""Processes that connect the vehicle to something outside it.

Each reaches the vehicle only as the aircraft's hardware would (bytes on serial lines,
MAVLink) plus, for the simulator, the simulation clock on the bus: ``jsbsim`` flies the
aircraft's physics and emulates its devices, ``sensor_models`` turns the true state into
what those devices measure, ``text_link`` speaks the thesis's 25-byte text link.
"""
