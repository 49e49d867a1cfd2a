"""The MAVLink link plug-in."""
