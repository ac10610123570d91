"""Missions: the xFLIE explore-inspect-explore executive and its run directory."""
