"""Control: vehicle modes, the commander, failsafes, missions, guidance and control laws,
and the flight controller that turns them into surface commands."""
