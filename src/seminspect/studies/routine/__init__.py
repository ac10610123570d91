"""The routine-inspection study (paper 002): every scenario over seeds on the mine drift, SA-TSP
against LKH, the tables of docs/reproduction.md and the acceptance checks.

* :mod:`.study`: the runs over seeds and the tour timings;
* :mod:`.checks`: issue 11's checks, per scenario and seed;
* :mod:`.tables`: the Markdown tables and the reproduction sections.
"""

from seminspect.studies.routine.study import RoutineStudy, run_study, tour_study
from seminspect.studies.routine.tables import reproduction_sections

__all__ = ["RoutineStudy", "reproduction_sections", "run_study", "tour_study"]
