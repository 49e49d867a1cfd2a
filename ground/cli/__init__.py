"""The ground commands of ``companion``: sim, replay, campaign."""
