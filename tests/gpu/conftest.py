"""Make the GPU tests' shared ensembles (gpu_cases.py) and the solver's tiny models
(tests/solve/solve_models.py) importable."""

import sys
from pathlib import Path

for _dir in (Path(__file__).parent, Path(__file__).parent.parent / "solve"):
    if str(_dir) not in sys.path:
        sys.path.insert(0, str(_dir))
