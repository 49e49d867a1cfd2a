"""Pure codecs for the wire protocols the vehicle speaks, and a reopening serial port.

Codecs take bytes or text and a reception time and return a bus message or a counted
rejection; they never touch a port, the bus or the clock. ``serial_port`` owns the port.
"""
