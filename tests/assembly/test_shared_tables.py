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


def test_a_constant_stiffness_table_is_kept_by_its_values():
    """The rectangular wave of a "constant" stiffness is computed once per set of values
    (a model's checks and assembly ask for it three times per mesh), each caller gets its
    own copy, and it is the wave of its definition."""
    import numpy as np
    import pytest

    from torquesplit.assembly import excitation
    from torquesplit.model.kinematics import solve_kinematics

    model = torquesplit.load_model("ji_li_mill_drive")
    kin = solve_kinematics(model)
    name = next(m for m, mesh in model.meshes.items() if mesh.stiffness.method == "constant")
    spec = model.meshes[name].stiffness
    excitation._constant_table.cache_clear()
    k = excitation.stiffness_table(model, kin, name, 512)
    again = excitation.stiffness_table(model, kin, name, 512)
    assert excitation._constant_table.cache_info().hits == 1
    assert again is not k and np.array_equal(again, k)  # (each caller's own copy)
    k[0] = -1.0
    assert excitation.stiffness_table(model, kin, name, 512)[0] == again[0]
    with pytest.raises(ValueError):  # (the one kept is read-only)
        excitation._constant_table(512, float(spec.value), float(spec.peak_to_peak),
                                   excitation._profile_contact_ratio(kin.meshes[name]))[0] = 1.0
    eps = excitation._profile_contact_ratio(kin.meshes[name])
    wave = excitation.contact_zone_wave(np.arange(512) / 512, spec.value, spec.peak_to_peak, eps)
    assert np.array_equal(again, wave)
    assert excitation.stiffness_table(model, kin, name, 256).shape == (256,)
