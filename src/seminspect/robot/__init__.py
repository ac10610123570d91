"""The simulated holonomic robot: ground and aerial modes, limits, collisions, trajectory log."""
