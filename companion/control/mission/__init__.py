"""Missions: the item model, validation, atomic storage; pure and replayable."""
