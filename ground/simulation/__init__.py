"""Simulated truth and sensors: shared by the JSBSim bridge and the synthetic flights.

The bridge turns JSBSim's state into device bytes; the synthetic flight generator turns a
kinematic trajectory into a sensor log. Both use the same error models, so a navigator
sees the same kind of sensor in a test, a benchmark and the simulator.
"""
