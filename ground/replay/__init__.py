"""``companion replay`` over one log or many, and its plots."""
