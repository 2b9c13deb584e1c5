"""Property test: any mutation of a valid model is either valid or a clean ModelError.

A valid model dict (one of the fixtures) is mutated one to three times -- a key
deleted, a leaf or a whole section replaced by junk (another type, a random string,
a negative, huge or non-finite number, a unit of the wrong dimension), a key renamed,
a section duplicated -- and loaded.  Every outcome must be a valid :class:`Model`, for
which the kinematics and the ``check`` summary then succeed too, or a
:class:`torquesplit.ModelError` whose issues are (location, message) strings.  Any
other exception is a bug: bad input must never end in a traceback.  Derandomised
(``derandomize=True``): CI draws the same examples every time, so a failure reproduces.
The corpus of whole files through the command line is ``tests/cli/test_fuzz_cli.py``.
"""

from __future__ import annotations

import json

import numpy as np
import re
import warnings

from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st
from model_fixtures import pair_dict, rich_dict

import torquesplit
from torquesplit.errors import ModelWarning
from torquesplit.model.summary import summary

#: words with which a message tells the user what to do
_FIX_VERBS = re.compile(
    r"\b(add|give|write|remove|correct|check|make|use|set|rename|delete|connect|fix|name|"
    r"increase|reduce|list|put|change)\b"
)

#: units of every kind the schema knows, so that most picks have the wrong dimension
WRONG_UNITS = [
    "50 kg", "3 s", "2 N/m", "100 rpm", "20 deg", "5 mm", "7 GPa", "1 kW", "3 N m",
    "1 kg m^2", "2 Hz", "1 N s/m", "4 N m/rad", "7850 kg/m^3", "0.01 Pa s", "20 degC",
    "1 m/s", "3 mm^2", "mm", "20", "",
]

#: numbers at the edges: zero, negative, huge, tiny, beyond float range.
EDGE_NUMBERS = [0, 0.0, -1, -1.5, -1e-9, 1e200, 1e300, -1e300, 10**30, 2**64, 10**400,
                -(10**400), 1e-300, 5e-324, 2**63 - 1]

#: names a mutation may rename a key to: other fields of the schema and typos
FIELD_NAMES = [
    "modul", "teeth", "module", "position", "place", "speed", "torque", "power", "body",
    "gears", "stiffness", "damping", "damping_ratio", "backlash", "axis", "dofs", "support",
    "mass", "polar_inertia", "from_gear", "angle", "hand", "helix_angle", "kind", "connects",
    "drives", "loads", "meshes", "shafts", "bodies", "model", "name", "pinion", "wheel",
]

junk = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e6, max_value=-1e-9),
    st.sampled_from(EDGE_NUMBERS),
    st.text(max_size=12),
    st.sampled_from(WRONG_UNITS),
    st.sampled_from(["pinion", "wheel", "motor", "balanced", "theta", "x", "right", "table"]),
    st.lists(st.one_of(st.integers(-5, 50), st.sampled_from(WRONG_UNITS)), max_size=4),
    st.dictionaries(st.sampled_from(FIELD_NAMES), st.integers(-3, 3), max_size=3),
)


def _paths(obj, prefix=()):
    """Every path (tuple of keys/indices) to a value inside ``obj``."""
    out = []
    if isinstance(obj, dict):
        items = obj.items()
    else:
        items = enumerate(obj) if isinstance(obj, list) else ()
    for key, value in items:
        out.append(prefix + (key,))
        out.extend(_paths(value, prefix + (key,)))
    return out


def _parent(data, path):
    node = data
    for key in path[:-1]:
        node = node[key]
    return node


def _mutate(data, draw) -> str:
    """Apply one random mutation to ``data`` in place; return a description."""
    paths = _paths(data)
    kind = draw(st.sampled_from(["delete", "replace_leaf", "replace_any", "rename", "duplicate"]))
    if kind == "delete":
        path = draw(st.sampled_from(paths))
        del _parent(data, path)[path[-1]]
    elif kind in ("replace_leaf", "replace_any"):
        pool = paths if kind == "replace_any" else [
            p for p in paths if not isinstance(_parent(data, p)[p[-1]], (dict, list))
        ] or paths
        path = draw(st.sampled_from(pool))
        _parent(data, path)[path[-1]] = draw(junk)
    elif kind == "rename":
        keyed = [p for p in paths if isinstance(p[-1], str)]
        path = draw(st.sampled_from(keyed))
        parent = _parent(data, path)
        new = draw(st.one_of(st.sampled_from(FIELD_NAMES), st.text(min_size=1, max_size=8)))
        parent[new] = parent.pop(path[-1])
    else:  # duplicate a section under a new name, or into another top-level collection
        tables = [p for p in paths if isinstance(_parent(data, p)[p[-1]], dict)] or [()]
        path = draw(st.sampled_from(tables))
        if not path:
            return "duplicate: nothing to duplicate"
        value = json.loads(json.dumps(_parent(data, path)[path[-1]]))
        target = draw(st.sampled_from(["sibling", "gears", "bodies", "meshes", "drives", "loads"]))
        if target == "sibling":
            parent = _parent(data, path)
            if isinstance(parent, list):
                parent.append(value)
            else:
                parent[f"{path[-1]}_copy"] = value
        else:
            data.setdefault(target, {})
            if isinstance(data[target], dict):
                data[target][str(path[-1])] = value
        path = (*path, f"-> {target}")
    return f"{kind} {'.'.join(map(str, path))}"


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow],
          derandomize=True, database=None)
@given(seed=st.sampled_from(["pair", "rich"]), n_mutations=st.integers(1, 3), data=st.data())
def test_mutated_model_is_valid_or_a_clean_model_error(seed, n_mutations, data):
    model_dict = pair_dict() if seed == "pair" else rich_dict()
    steps = []
    for _ in range(n_mutations):
        if not isinstance(model_dict, dict) or not _paths(model_dict):
            break
        steps.append(_mutate(model_dict, data.draw))
    note(f"mutations: {steps}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            model = torquesplit.load_model(model_dict)
        except torquesplit.ModelError as exc:
            assert exc.issues, "a ModelError must list at least one issue"
            for loc, msg in exc.issues:
                assert isinstance(loc, str) and isinstance(msg, str) and msg.strip()
                assert "Traceback" not in msg
                # the message ends with what to do (names in it may contain ';' too)
                assert ";" in msg and _FIX_VERBS.search(msg.split(";", 1)[1]), (loc, msg)
            return
        # a valid model: the kinematics, the check summary and the assembly work too
        try:
            torquesplit.solve_kinematics(model)
            json.dumps(summary(model))
            structure = torquesplit.assemble(model)
        except torquesplit.ModelError:
            return
        assert np.all(np.isfinite(structure.inv_mass))


def test_fixtures_are_valid():
    for d in (pair_dict(), rich_dict()):
        torquesplit.load_model(d)
