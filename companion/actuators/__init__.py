"""Servo output libraries: the airframe's channel map and the Mini SSC II wire format."""
