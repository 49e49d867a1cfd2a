"""Navigation maths, free of bus and clock: each estimator takes samples with their times."""
