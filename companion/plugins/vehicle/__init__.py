"""Vehicle-level plug-ins: the commander (modes, home, guided target)."""
