"""On-board software of a MAVLink companion computer for a small fixed-wing UAV."""

__version__ = "0.1.0"
