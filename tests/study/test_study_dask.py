"""A Dask cluster gives the same dataset as the local pool (same driver, another runner)."""

from __future__ import annotations

import pytest
import tomli_w
import xarray as xr
from typer.testing import CliRunner

from study_helpers import grid_study
from torquesplit.cli import app
from torquesplit.study import Study

distributed = pytest.importorskip("distributed")


def test_local_cluster_equals_local_pool(split_file, tmp_path):
    data = grid_study(split_file, [
        {"path": "meshes.a1.stiffness", "values": ["3e8 N/m", "5e8 N/m"]},
        {"path": "meshes.b2.transmission_error.constant", "values": ["0 um", "6 um"]}])
    study = Study(data)
    local = study.run(workers=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=40) as cluster:
        with distributed.Client(cluster) as client:
            on_dask = study.run(client=client, out=tmp_path / "dask", figures=False)
            workers = {w for w in xr.open_dataset(tmp_path / "dask" / "results.nc",
                                                  engine="h5netcdf")["status"].values.ravel()}
            # the command line reaches the same cluster by its scheduler address
            path = tmp_path / "s.toml"
            path.write_text(tomli_w.dumps(data))
            res = CliRunner().invoke(app, ["study", str(path), "--scheduler",
                                           cluster.scheduler_address, "--out",
                                           str(tmp_path / "cli"), "--quiet", "--no-figures"])
            assert res.exit_code == 0, res.output
    by_address = xr.open_dataset(tmp_path / "cli" / "results.nc", engine="h5netcdf")
    xr.testing.assert_equal(local.drop_vars("case_wall_time"),
                            by_address.drop_vars("case_wall_time"))
    xr.testing.assert_identical(local.drop_vars("case_wall_time"),
                                on_dask.drop_vars("case_wall_time"))
    assert workers == {"ok"}
    # the cases ran on the cluster's processes, not in this one
    import os
    import sqlite3

    with sqlite3.connect(tmp_path / "dask" / "study.sqlite") as db:
        pids = {w.split(":")[-1] for (w,) in db.execute("SELECT worker FROM cases")}
    assert str(os.getpid()) not in pids
