"""Pure codecs for the wire protocols the vehicle speaks, and a reopening serial port."""
