"""Flight campaigns: many lockstep simulated flights, scored from the truth, on Ray."""
