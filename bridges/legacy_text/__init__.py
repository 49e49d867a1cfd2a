"""The thesis's 25-byte text link, kept for its ground station: a translator between that
link on a serial line and the vehicle's MAVLink."""
