"""The learned-inspection study (paper 004 Tables I-III): the tables beside the paper's numbers,
from stored evaluations."""

from seminspect.studies.learning.tables import (
    ablation_markdown,
    reproduction_sections,
    table1_markdown,
)

__all__ = ["ablation_markdown", "reproduction_sections", "table1_markdown"]
