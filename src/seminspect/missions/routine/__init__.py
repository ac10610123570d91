"""Routine inspection on an outdated map (paper 002)."""
