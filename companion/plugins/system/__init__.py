"""System plug-ins: the on-board flight logger."""
