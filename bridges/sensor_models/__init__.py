"""The simulated aircraft's true state and what its sensors make of it (noise, bias, battery)."""
