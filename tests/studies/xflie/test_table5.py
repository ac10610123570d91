"""The planning study's Table 5 tables: the condensed table of docs/reproduction.md."""

from seminspect.studies.xflie.table5 import both_volumes_beside_paper
from study_fakes import study


def test_the_condensed_table_5_puts_both_volumes_beside_the_paper() -> None:
    ground, full = study(vp_s=0.03).table5, study(vp_s=0.3).table5
    lines = both_volumes_beside_paper(ground, full)
    assert lines[0] == "| Measure (median unless stated) | S3 ours | S3 paper |"
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in lines[2:]]
    rows = {row[0]: row[1:] for row in cells}
    assert rows["VP at 0.5 m, ground band (ms)"][:2] == ["45.00", "1700.00"]  # 30 and 60 ms
    assert rows["VP at 0.5 m, full volume (ms)"][0] == "450.00"
    assert rows["VP/HP time at 0.5 m, searches, full (median / min)"][0] == "75,000 / 50,000"
    assert rows["valid segments: graph edges, HP, refined, VP 0.5 m"][0].startswith("97.6% of 41")
    assert "full volume" not in "\n".join(both_volumes_beside_paper(ground, []))
