"""Labelled triangle-mesh worlds (instance / class / part per face), generators and user worlds."""
