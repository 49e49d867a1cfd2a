"""The JSBSim simulator bridge: the aircraft's physics, and its devices on pseudo-terminals.

It reaches the vehicle only as the aircraft's hardware would (bytes on serial lines) plus
the simulation clock (and, for tools, the true state) on the bus.
"""
