"""One-line messages where a reviewer met raw ones (TOML syntax error for a .csv, a raw
FileExistsError, scipy's 'f(a) and f(b) must have different signs')."""

import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.errors import ModelError

runner = CliRunner()


@pytest.mark.parametrize("suffix", [".csv", ".mat"])
def test_report_of_an_export_says_it_reads_netcdf(tmp_path, suffix):
    f = tmp_path / f"r{suffix}"
    f.write_text("a,b\n1,2\n")
    res = runner.invoke(app, ["report", str(f)])
    assert res.exit_code == 2 and "'report' reads the NetCDF results" in res.stderr


def test_a_results_file_given_as_a_model_is_named_as_such(tmp_path):
    f = tmp_path / "r.nc"
    f.write_bytes(b"\x89HDF\r\n" + b"\0" * 5_000_000)
    with pytest.raises(ModelError, match="is a results file"):
        torquesplit.load_model(f)


def test_an_impossible_contact_load_is_said_in_words():
    res = runner.invoke(app, ["contact", "ji_li_mill_drive", "--pair", "m11", "--load", "1e9 N",
                              "--harris", "0"])
    assert res.exit_code == 2 and "too large for this tooth geometry" in res.stderr, res.stderr
