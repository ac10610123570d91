"""Planning: target utility (eq 6), hierarchical and semantic planning, view planning, baselines."""
