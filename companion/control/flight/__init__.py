"""The flight controller: modes, the mission executor and the control laws put together."""
