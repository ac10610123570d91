"""The planning study (000 Table 5, Fig 13, Table 6): hierarchical planner vs the volumetric
baseline, on the missions' final graphs, as the mission's navigator, and on cities of growing
size.

* :mod:`.paper`: 000's rows of Table 5 and cells of Table 6;
* :mod:`.missions`: the city missions the study runs or reuses, Table 6's columns of a run;
* :mod:`.queries`: which operator queries a mission's final graph is asked;
* :mod:`.comparison`: one query timed with both planners, paths checked against the world;
* :mod:`.study`: Table 5's records of a run's queries, and the whole study run end to end;
* :mod:`.scaling`: synthetic cities of growing size (Fig 13);
* :mod:`.cells`, :mod:`.table5`, :mod:`.table6`: the Markdown tables beside the paper's numbers;
* :mod:`.tables`: the study's files: the Markdown, the scaling plot, the JSON.
"""

from seminspect.studies.xflie.study import PlanningStudy, run_study
from seminspect.studies.xflie.tables import write_study

__all__ = ["PlanningStudy", "run_study", "write_study"]
