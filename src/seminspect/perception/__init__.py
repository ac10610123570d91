"""Perception: from sensor frames to semantic observations (detection, localisation, similarity)."""
