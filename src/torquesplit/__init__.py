"""torquesplit: dynamic load-sharing analysis of power-split gear transmissions.

The pipeline, one stage per subpackage (each stage returns a new object)::

    load_model(file)            -> Model       (model/: schema, units, checks)
    solve_kinematics(model)     -> Kinematics  (model/: speeds, torques, line of action)
    assemble(model)             -> Structure   (assembly/: DOFs, mass, element arrays)
    simulate(model, ...)        -> Results     (solve/ + metrics/ + results/)
    quasi_static_load_sharing(model) -> QuasiStaticResults (equilibria over mesh positions)
    model_modes(model)          -> ModalReport (natural modes about the static equilibrium)
    steady_state(model, speed=...) -> SteadyState (steady/: periodic state; sweep_speed,
                                                campbell over a speed range)
    load_results(file.nc)       -> Results     (a saved run, its metrics recomputed)
    run_study(study_file)       -> Dataset     (study/: grids, Monte Carlo, sensitivity)
    contact_analysis(model, mesh, loads) -> ContactAnalysis (gears/contact/: loaded tooth
                                                contact analysis of one mesh)
    save(result, "file.mat")    -> Path        (any of these results, by suffix: .nc,
                                                .mat, .csv; as the commands write them)
"""

from __future__ import annotations

from .errors import (ModelError, ModelWarning, OptionError, OptionTypeError, OutputError,
                     SolverError, StepTooLargeError, StudyError, TorquesplitError)
from .examples import example_names, example_path

__version__ = "0.1.0"

__all__ = [
    "ModelError", "ModelWarning", "OptionError", "OptionTypeError", "OutputError",
    "SolverError",
    "StepTooLargeError", "StudyError", "TorquesplitError", "example_names", "example_path",
    "load_model", "solve_kinematics", "assemble", "simulate", "quasi_static_load_sharing",
    "model_modes", "steady_state", "sweep_speed", "campbell", "load_results",
    "open_results", "Results", "Model", "SteadyState", "Study", "run_study",
    "contact_analysis", "save",
]

#: loaded only when asked for (pydantic, numba, xarray, the study and steady-state
#: layers): 'import torquesplit' itself is light, so that the command's entry point
#: (:mod:`torquesplit._launch`) can turn a Ctrl-C while the rest loads into one line; the
#: classes functions return, so that a user can name them (isinstance, annotations)
_LAZY = {"load_model": "model.io", "solve_kinematics": "model.kinematics",
         "assemble": "assembly.assemble", "simulate": "simulation",
         "model_modes": "modes", "quasi_static_load_sharing": "quasistatic",
         "Study": "study", "run_study": "study", "steady_state": "steady",
         "sweep_speed": "steady", "campbell": "steady", "load_results": "results",
         "open_results": "results", "Results": "results", "SteadyState": "steady",
         "Model": "model.schema", "contact_analysis": "gears.contact.export",
         "save": "results.export"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'torquesplit' has no attribute {name!r}")


def __dir__():
    # (globals() holds 'annotations', the __future__ feature: not the library's)
    return sorted((set(globals()) | set(__all__)) - {"annotations"})
