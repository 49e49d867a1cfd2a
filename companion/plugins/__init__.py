"""The thin plug-ins: one file per plug-in, one folder per kind."""
