"""Device plug-ins that publish raw sensor readings."""
