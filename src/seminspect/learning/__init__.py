"""Learned inspection (004): the semantic inspection environment, its policy and training."""
