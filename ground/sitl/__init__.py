"""The vehicle flying in JSBSim: the simulator bridge, one vehicle session, fleets."""
