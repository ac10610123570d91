"""Terrain mapping (paper 001, phase 1): a drive through a simulated site into a semantic cloud."""
