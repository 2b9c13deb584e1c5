"""torquesplit: dynamic load-sharing analysis of power-split gear transmissions.

The pipeline, one stage per subpackage (each stage returns a new object)::

    load_model(file)            -> Model       (model/: schema, units, checks)
    solve_kinematics(model)     -> Kinematics  (model/: speeds, torques, line of action)
    assemble(model)             -> Structure   (assembly/: DOFs, mass, element arrays)
    simulate(model, ...)        -> Results     (solve/ + metrics/ + results/)
"""

from __future__ import annotations

from .assembly.assemble import assemble
from .errors import ModelError, ModelWarning, SolverError, StepTooLargeError, TorquesplitError
from .examples import example_names, example_path
from .model.io import load_model
from .model.kinematics import solve_kinematics
from .simulation import simulate

__version__ = "0.1.0"

__all__ = [
    "ModelError", "ModelWarning", "SolverError", "StepTooLargeError", "TorquesplitError",
    "example_names", "example_path", "load_model", "solve_kinematics", "assemble", "simulate",
]
