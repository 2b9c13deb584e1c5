"""Ctrl-C: one line and status 130 wherever it lands, and a speed sweep keeps its curve."""

import pytest
import typer
from typer.testing import CliRunner

from torquesplit import cli_support as ux
from torquesplit.cli import app


def _chained_interrupt():
    """What numba raises when Ctrl-C lands inside compiled code (seen in 'contact')."""
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as inner:
            raise SystemError("_numba_unpickle returned a result with an exception set") from inner
    except SystemError as middle:
        raise SystemError("CPUDispatcher(ltca_solve) returned a result with an exception "
                          "set") from middle


def test_an_interrupt_inside_compiled_code_is_an_interrupt():
    with pytest.raises(typer.Exit) as info:
        with ux.interruptible():
            _chained_interrupt()
    assert info.value.exit_code == 130
    with pytest.raises(SystemError, match="unrelated"):  # any other SystemError is a bug
        with ux.interruptible():
            raise SystemError("unrelated")


def test_contact_refuses_more_positions_than_the_model_file_allows():
    """--positions 100000 ran for minutes without an estimate, and segfaulted on Ctrl-C."""
    res = CliRunner().invoke(app, ["contact", "ji_li_mill_drive", "--pair", "m11",
                                   "--positions", "100000"])
    assert res.exit_code == 2 and "--positions 100000 is more than 4096" in res.stderr


def test_an_interrupted_speed_sweep_keeps_its_curve(monkeypatch):
    """Ctrl-C during 'sweep-speed' exited 130 and wrote nothing; other stops keep the curve."""
    from torquesplit.steady import sweep as S

    calls = {"n": 0}
    real = S.ShootingContinuation.multipliers

    def interrupt_on_the_third_point(self, x, s):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(self, x, s)

    monkeypatch.setattr(S.ShootingContinuation, "multipliers", interrupt_on_the_third_point)
    from torquesplit import example_path
    from torquesplit.steady.maps import sweep_speed

    ds = sweep_speed(example_path("ji_li_mill_drive"), 300 * 0.10472, 1500 * 0.10472,
                     points=30)
    assert ds.sizes["point"] == 2 and not ds.attrs["complete"]
    assert ds.attrs["message"].startswith("interrupted (Ctrl-C) after 2 points")
