"""Set-ups of one process share equal phase tables (14.7 MB a set for Ji & Li's drive)."""

from __future__ import annotations

import gc
import warnings

import torquesplit
from torquesplit.assembly import tables
from torquesplit.simulation import prepare_run


def _run(**changes):
    model = torquesplit.load_model("ji_li_mill_drive")
    if changes:
        model = model.with_changes(changes)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare_run(model, duration=1e-3)


def test_equal_tables_are_one_object_and_other_ones_are_not():
    a = _run()
    b = _run(**{"meshes.m11.damping_ratio": 0.09})  # same tables
    c = _run(**{"meshes.m11.backlash": "0.3 mm"})  # same tables (a gap is no table)
    for f in tables.TABLES:
        assert getattr(a.structure, f) is getattr(b.structure, f) is getattr(c.structure, f)
    d = _run(**{"gears.z1.errors.eccentricity": "30 um"})  # an error: its own tables?
    same = all(tables.bits_equal(getattr(a.structure, f), getattr(d.structure, f))
               for f in tables.TABLES)
    assert (d.structure.stiffness_table is a.structure.stiffness_table) == same


def test_a_shared_set_is_held_weakly():
    """Nothing keeps a table set once no structure of this process uses it."""
    import weakref

    a = _run(**{"meshes.m11.stiffness.value": "4.41e9 N/m"})  # a set of its own
    ref = weakref.ref(a.structure.stiffness_table)
    del a
    gc.collect()
    assert ref() is None
