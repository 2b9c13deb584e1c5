"""torquesplit.load_results (a run's file) and torquesplit.study.load_results (a study's
folder) say which one a path needs when given the other's."""

from __future__ import annotations

import pytest

import torquesplit
from torquesplit.errors import OutputError

SPEC = {"study": {"name": "names", "model": "ji_li_mill_drive",
                  "outputs": ["load_sharing.engineering"]},
        "analysis": {"duration": "0.05 s"},
        "grid": {"parameters": [{"path": "meshes.m11.damping_ratio", "values": [0.05]}]}}


def test_each_load_results_names_the_other(tmp_path):
    out = tmp_path / "s"
    torquesplit.Study(SPEC).run(out=out, workers=1, figures=False)
    ds = torquesplit.study.load_results(out)
    assert "load_sharing.engineering" in ds
    ds.close()
    with pytest.raises(OutputError, match=r"a study's folder.*torquesplit\.study\.load_results"):
        torquesplit.load_results(out)
    with pytest.raises(OutputError, match=r"a file, not a study's folder.*torquesplit\.load"):
        torquesplit.study.load_results(out / "results.nc")
    (out / "results.nc").unlink()
    with pytest.raises(OutputError, match="has not finished.*resume"):
        torquesplit.study.load_results(out)
    with pytest.raises(OutputError, match="no such folder"):
        torquesplit.study.load_results(tmp_path / "nowhere")
    with pytest.raises(OutputError, match="not a study's folder"):
        torquesplit.study.load_results(tmp_path)
