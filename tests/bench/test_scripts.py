"""Every benchmark script still imports: a script that no longer runs is a published figure
nobody can regenerate (the imports are where a moved or renamed name breaks it)."""

from __future__ import annotations

import pytest

from bench_scripts import BENCH, bench_script

#: Scripts that need an optional extra to import at all, and the module that provides it.
NEEDS = {"rl_policy": "torch", "rl_reproduction": "torch"}


@pytest.mark.parametrize("name", sorted(p.stem for p in BENCH.glob("*.py")))
def test_the_script_imports(name: str) -> None:
    if name in NEEDS:
        pytest.importorskip(NEEDS[name])
    assert callable(getattr(bench_script(name), "main", None)), f"bench/{name}.py has no main()"
