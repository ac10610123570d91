"""The planning study (000 Table 5, Fig 13, Table 6): hierarchical planner vs the volumetric
baseline, on the missions' final graphs, as the mission's navigator, and on cities of growing
size.

* :mod:`.comparison`: one query timed with both planners, paths checked against the world;
* :mod:`.scaling`: synthetic cities of growing size (Fig 13);
* :mod:`.study`: the paper's rows, the city missions it runs or reuses, query choice, records;
* :mod:`.tables`: the Markdown tables beside the paper's numbers, the scaling plot, the JSON.
"""

from seminspect.studies.xflie.study import PlanningStudy, run_study
from seminspect.studies.xflie.tables import write_study

__all__ = ["PlanningStudy", "run_study", "write_study"]
