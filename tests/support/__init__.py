"""Helpers shared by the tests: test plug-ins and a running-vehicle fixture."""
