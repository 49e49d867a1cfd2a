"""Several complete simulated vehicles at once (`companion sim --count N`)."""
