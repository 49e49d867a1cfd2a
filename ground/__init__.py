"""What stays on the ground: the simulator and its bridge, fleets, campaigns, replay
batches and plots. Nothing on board imports this package."""
