"""Terrain-aware, task-driven outdoor scene graphs (001 Sec III)."""
