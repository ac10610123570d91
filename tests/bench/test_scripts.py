"""Every benchmark script still imports: a script that no longer runs is a published figure
nobody can regenerate (the imports are where a moved or renamed name breaks it)."""

from __future__ import annotations

import pytest

from bench_scripts import BENCH, bench_script

#: Scripts that need an optional extra to import at all, and the module that provides it.
NEEDS = {"rl_crashes": "torch", "rl_policy": "torch", "rl_reproduction": "torch"}


@pytest.mark.parametrize("name", sorted(p.stem for p in BENCH.glob("*.py")))
def test_the_script_imports(name: str) -> None:
    if name in NEEDS:
        pytest.importorskip(NEEDS[name])
    assert callable(getattr(bench_script(name), "main", None)), f"bench/{name}.py has no main()"


def test_the_rl_environment_benchmark_runs(monkeypatch, capsys) -> None:
    """bench/rl_env.py reached into the ray caster's private scene, and later cast with the
    old cylinder arguments, and stopped running; its quick form (1 and 8 rooms of both sets)
    runs here so that its published speeds stay regenerable."""
    monkeypatch.setattr("sys.argv", ["rl_env.py", "--quick"])
    bench_script("rl_env").main()
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[1:]]
    assert [tuple(r[:4]) for r in rows] == [
        (rooms_set, rooms, policy, threads)
        for rooms_set in ("train", "table1")
        for rooms in ("1", "8")
        for policy in ("random", "orbit")
        for threads in ("1", "2")
    ]
    assert all(float(r[4].replace(",", "")) > 0 and float(r[8]) > 0 for r in rows)
    assert all(0 <= int(r[6].rstrip("%")) <= 100 for r in rows)  # the in-view share
