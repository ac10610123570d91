"""The learned-inspection study (paper 004 Tables I-III)."""
