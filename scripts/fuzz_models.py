"""Nightly-style fuzz: thousands of malformed model files through ``torquesplit check``.

    python scripts/fuzz_models.py                     # 10,000 mutants, 2 workers
    python scripts/fuzz_models.py --count 500 --workers 1
    python scripts/fuzz_models.py --start 1234 --count 1 --show   # one mutant, in full

Each mutant of ``tests/fuzz_corpus.py`` (deterministic: mutant i is always the same file)
is written to a temporary file and checked by the real CLI (in-process, in a worker
process with a memory limit).  A mutant that takes longer than ``--timeout`` seconds
is a hang: its worker is killed and replaced.  With ``--run``, every accepted mutant
is also run briefly (two periods of its fastest mesh, ``--run-timeout`` seconds at
most), and any refusal other than a :class:`~torquesplit.errors.SolverError` is counted
as a failure of ``check``; a slow run is counted apart (its cost is the step the
stability check chooses, not a failure of ``check``).

Prints the counts by outcome (``ok``, ``error`` = clean one-line errors with exit 2,
and every kind of failure) and the first examples of each failure; exits 1 if any
mutant failed.  ``--json FILE`` writes the counts and failures.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import select
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = [str(ROOT / "tests"), str(ROOT / "tests" / "model")]

CLEAN = ("ok", "error")


# --------------------------------------------------------------------------- worker
def _worker(memory_gib: float) -> None:  # pragma: no cover - runs in a subprocess
    """Read mutant indices on stdin, write one JSON result per line on stdout."""
    import resource

    limit = int(memory_gib * 2**30)
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    sys.path[:0] = TESTS
    from typer.testing import CliRunner

    from fuzz_corpus import judge, mutant
    from torquesplit.cli import app

    runner = CliRunner()
    folder = Path(tempfile.mkdtemp(prefix="torquesplit-fuzz-"))
    out = sys.stdout
    sys.stdout = sys.stderr  # nothing but results on the pipe
    for line in sys.stdin:
        index, seed, do_run = json.loads(line)
        desc, raw, suffix = mutant(index, seed)
        path = folder / f"mutant{suffix}"
        path.write_bytes(raw)
        t0 = time.perf_counter()
        try:
            res = runner.invoke(app, ["check", str(path)])
            verdict = judge(res.exit_code, res.stdout, res.stderr, res.exception)
            stderr = res.stderr
            if res.exception is not None and not isinstance(res.exception, SystemExit):
                stderr = f"{type(res.exception).__name__}: {res.exception}"
        except MemoryError:
            verdict, stderr = "memory", "MemoryError"
        seconds = time.perf_counter() - t0
        will_run = bool(do_run and verdict == "ok")
        out.write(json.dumps({"index": index, "desc": desc, "verdict": verdict,
                              "stderr": stderr[:400], "seconds": seconds, "run": None,
                              "more": will_run}) + "\n")
        out.flush()
        if will_run:
            t0 = time.perf_counter()
            run = _short_run(path)
            out.write(json.dumps({"run": run, "run_seconds": time.perf_counter() - t0}) + "\n")
            out.flush()


def _short_run(path: Path) -> str:  # pragma: no cover - runs in a subprocess
    import warnings

    import torquesplit
    from torquesplit.errors import SolverError

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            model = torquesplit.load_model(path)
            kin = torquesplit.solve_kinematics(model)
            f_max = max(mk.frequency for mk in kin.meshes.values())
            res = torquesplit.simulate(model, duration=2 / f_max, steps_per_period=10,
                                       rhs="general")
            return "ran" if res.success else "stopped"
        except SolverError:
            return "solver error"
        except Exception as exc:  # noqa: BLE001 - the finding
            return f"refused: {type(exc).__name__}: {str(exc)[:200]}"


class _Worker:
    def __init__(self, args):
        self.args = args
        self.start()

    def start(self):
        env = dict(os.environ)
        env["PYTHONPATH"] = self.args.src or str(ROOT / "src")
        self.proc = subprocess.Popen(
            [sys.executable, __file__, "--_worker", str(self.args.memory)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            env=env, text=True, bufsize=1)
        self.index = None
        self.since = 0.0
        self.pending = None  # the check result of a mutant whose short run is going on

    def send(self, index):
        self.index = index
        self.pending = None
        self.since = time.monotonic()
        self.proc.stdin.write(json.dumps([index, self.args.seed, self.args.run]) + "\n")
        self.proc.stdin.flush()

    def kill(self):
        self.proc.kill()
        self.proc.wait()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--count", type=int, default=10_000)
    p.add_argument("--start", type=int, default=0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--timeout", type=float, default=10.0, help="seconds per mutant")
    p.add_argument("--memory", type=float, default=3.0, help="GiB per worker")
    p.add_argument("--run", action="store_true", help="also run the accepted mutants")
    p.add_argument("--run-timeout", type=float, default=60.0,
                   help="seconds per short run (a slow run is reported, not a failure)")
    p.add_argument("--show", action="store_true", help="print each mutant's file and result")
    p.add_argument("--json", type=Path, help="write counts and failures here")
    p.add_argument("--src", help="torquesplit sources to test (default: this checkout)")
    p.add_argument("--_worker", type=float, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args._worker is not None:
        _worker(args._worker)
        return 0
    if args.show:
        sys.path[:0] = TESTS
        from fuzz_corpus import mutant

        for i in range(args.start, args.start + args.count):
            desc, raw, suffix = mutant(i, args.seed)
            print(f"--- mutant {i} ({suffix}): {desc}\n{raw[:2000]!r}")

    todo = list(range(args.start, args.start + args.count))
    todo.reverse()
    workers = [_Worker(args) for _ in range(max(1, args.workers))]
    results = []
    t0 = time.monotonic()
    busy = {}
    reported = 0
    while todo or busy:
        for w in workers:
            if w.index is None and todo:
                w.send(todo.pop())
                busy[w.proc.stdout.fileno()] = w
        ready, _, _ = select.select(list(busy), [], [], 0.5)
        for fd in ready:
            w = busy.pop(fd)
            line = w.proc.stdout.readline()
            if not line:  # the worker died (memory limit, crash)
                results.append({"index": w.index, "desc": "", "verdict": "worker died",
                                "stderr": "", "seconds": time.monotonic() - w.since,
                                "run": None})
                w.kill()
                w.start()
                continue
            result = json.loads(line)
            if w.pending is not None:  # the short run of an accepted mutant
                w.pending.update(run=result["run"], run_seconds=result["run_seconds"])
                results.append(w.pending)
                w.index = w.pending = None
            elif result.pop("more"):
                w.pending = result
                w.since = time.monotonic()
                busy[fd] = w
            else:
                results.append(result)
                w.index = None
        now = time.monotonic()
        for fd, w in list(busy.items()):
            if w.pending is not None and now - w.since > args.run_timeout:
                del busy[fd]
                w.pending["run"] = f"slow: more than {args.run_timeout:g} s"
                results.append(w.pending)
                w.kill()
                w.start()
            elif w.pending is None and now - w.since > args.timeout:
                del busy[fd]
                results.append({"index": w.index, "desc": "", "verdict": "hang",
                                "stderr": "", "seconds": now - w.since, "run": None})
                w.kill()
                w.start()
        if len(results) // 1000 > reported:
            reported = len(results) // 1000
            print(f"  {len(results)} / {args.count} ({time.monotonic() - t0:.0f} s)",
                  file=sys.stderr)
    for w in workers:
        w.proc.stdin.close()
        w.kill()

    results.sort(key=lambda r: r["index"])
    counts = collections.Counter(r["verdict"] for r in results)
    runs = collections.Counter((r["run"] or "").split(":")[0] for r in results if r["run"])
    failures = [r for r in results if r["verdict"] not in CLEAN
                or (r["run"] or "").startswith("refused")]
    wall = time.monotonic() - t0
    print(f"{len(results)} mutants in {wall:.0f} s ({args.workers} workers)")
    for verdict, n in counts.most_common():
        print(f"  {verdict:18s} {n}")
    if runs:
        print("accepted mutants, short run:")
        for what, n in runs.most_common():
            print(f"  {what:18s} {n}")
    if args.show:
        for r in results:
            print(json.dumps(r))
    by_kind = collections.defaultdict(list)
    for r in failures:
        by_kind[r["verdict"] if r["verdict"] not in CLEAN else "run refused"].append(r)
    for kind, rs in by_kind.items():
        print(f"{kind}: {len(rs)}, e.g. " + "; ".join(
            f"#{r['index']} {r['desc'][:80]} {r['stderr'][:120]!r} {r['run'] or ''}"
            for r in rs[:3]))
    if args.json:
        args.json.write_text(json.dumps({"counts": counts, "runs": runs, "seconds": wall,
                                         "failures": failures}, indent=1))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
