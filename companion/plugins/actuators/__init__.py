"""Actuator plug-ins: the servo card."""
