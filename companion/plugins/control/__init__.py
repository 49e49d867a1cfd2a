"""Control plug-ins: the fixed-wing flight controller."""
