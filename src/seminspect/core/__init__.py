"""Foundations shared by every layer: errors, atomic I/O, seeded randomness, paper parameters."""
