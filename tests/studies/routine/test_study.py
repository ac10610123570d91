"""The routine study's runs: every adaptive run found, the figures as JSON, a run that stopped
early refused, and SA-TSP timed against LKH."""

import pytest

from seminspect.core.errors import SeminspectError
from seminspect.missions.routine.run import RoutineResult
from seminspect.studies.routine import study as routine_study
from seminspect.studies.routine.study import RoutinePair, RoutineStudy, run_study, tour_study


def test_the_study_lists_its_adaptive_runs_and_writes_every_figure(make_metrics) -> None:
    nominal, adaptive, baseline = make_metrics(), make_metrics("receding"), make_metrics("receding")
    study = RoutineStudy(
        {"nominal": {0: nominal}}, {"receding": {0: RoutinePair(adaptive, baseline)}}, (0,)
    )
    assert study.adaptive_runs() == [nominal, adaptive]
    document = study.to_json()
    assert list(document) == ["single", "pairs", "seeds"] and document["seeds"] == [0]
    assert document["single"]["nominal"][0] == nominal.to_json()
    assert document["pairs"]["receding"][0]["baseline"] == baseline.to_json()


def test_a_run_that_stopped_before_its_mission_was_built_is_refused(tmp_path, monkeypatch) -> None:
    def stopped(config, out, **_):
        return RoutineResult(out, "interrupted", "stopped by SIGTERM", None)

    monkeypatch.setattr(routine_study, "run_routine", stopped)
    with pytest.raises(SeminspectError, match="stopped by SIGTERM"):
        run_study(tmp_path, (0,))


@pytest.mark.slow
def test_sa_tsp_is_timed_against_lkh_on_growing_grids() -> None:
    tours = tour_study()
    assert [t.views for t in tours] == sorted({t.views for t in tours})  # growing, distinct
    for t in tours:
        assert t.lkh_length_m <= t.sa_length_m + 1e-9 and t.gap_pct <= 5.0
        assert t.sa_ms > 0 and t.lkh_ms > 0
