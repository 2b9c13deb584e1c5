"""A Dask cluster gives the same dataset as the local pool (same driver, another runner)."""

from __future__ import annotations

import pytest
import xarray as xr

from study_helpers import grid_study
from torquesplit.study import Study

distributed = pytest.importorskip("distributed")


def test_local_cluster_equals_local_pool(split_file, tmp_path):
    study = Study(grid_study(split_file, [
        {"path": "meshes.a1.stiffness", "values": ["3e8 N/m", "5e8 N/m"]},
        {"path": "meshes.b2.transmission_error.constant", "values": ["0 um", "6 um"]}]))
    local = study.run(workers=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=40) as cluster:
        with distributed.Client(cluster) as client:
            on_dask = study.run(client=client, out=tmp_path / "dask")
            workers = {w for w in xr.open_dataset(tmp_path / "dask" / "results.nc",
                                                  engine="h5netcdf")["status"].values.ravel()}
    xr.testing.assert_identical(local.drop_vars("case_wall_time"),
                                on_dask.drop_vars("case_wall_time"))
    assert workers == {"ok"}
    # the cases ran on the cluster's processes, not in this one
    import os
    import sqlite3

    with sqlite3.connect(tmp_path / "dask" / "study.sqlite") as db:
        pids = {w.split(":")[-1] for (w,) in db.execute("SELECT worker FROM cases")}
    assert str(os.getpid()) not in pids
