"""Estimator plug-ins that turn sensor channels into nav/state."""
