"""benchmarks/bench_kernel_parts.py times an RK4 step with parts of ``solve/_kernels.py``
removed by text; a part whose text the kernels no longer contain is reported as
skipped, so that an edit of the kernels would silently drop a row of the benchmark
(benchmarks/RESULTS.md, "Where a Ji & Li RK4 step goes").  Here every removal must still
apply."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    path = ROOT / "benchmarks" / "bench_kernel_parts.py"
    spec = importlib.util.spec_from_file_location("bench_kernel_parts", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_part_of_the_step_benchmark_is_found_in_the_kernels():
    bench = _bench()
    source = bench.KERNELS.read_text(encoding="utf-8")
    missing = [part for part, removals in bench.REMOVALS.items()
               if bench._patched(source, removals) is None]
    assert not missing, (f"bench_kernel_parts.py no longer finds {missing} in "
                         f"solve/_kernels.py: update its REMOVALS")


def test_a_removal_changes_the_source_and_a_stale_one_is_refused():
    bench = _bench()
    source = bench.KERNELS.read_text(encoding="utf-8")
    for part, removals in bench.REMOVALS.items():
        assert bench._patched(source, removals) != source, part
    assert bench._patched(source, [("text that is not in the kernels", "")]) is None
