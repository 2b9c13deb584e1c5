"""Studies of a ``[[planetary]]`` stage: its own fields can be varied (cases start from
the file's data, where the stage table is) and its mesh-load factor K_gamma
(``planet_load_sharing.*``) is an output of run and static studies."""

from __future__ import annotations

import numpy as np
import pytest
import tomli_w
from planetary_models import lp_raw

from torquesplit.study import Study, run_study
from torquesplit.study.errors import StudyError


@pytest.fixture
def lp_file(tmp_path):
    """Lin & Parker's 4-planet stage with a zero pin error on every planet (a field the
    study varies)."""
    path = tmp_path / "lp.toml"
    data = lp_raw(4, pin_errors=[{"tangential": "0 um"} for _ in range(4)])
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    return path


def _study(model, path, outputs, analysis):
    return {"study": {"name": "pin", "model": str(model), "outputs": outputs},
            "analysis": analysis,
            "grid": {"parameters": [{"path": path, "values": ["0 um", "10 um"]}]}}


def test_a_stage_field_varies_and_k_gamma_is_an_output(lp_file):
    """A tangential pin error on planet 1 loads it (static: K_gamma 1 without it, > 1
    with it); planet 2's factor and the stage's are outputs by name."""
    ds = run_study(_study(lp_file, "planetary.0.pin_errors.0.tangential",
                          ["planet_load_sharing.*"],
                          {"type": "static", "revolutions": 0.02}))
    assert set(ds["status"].values) == {"ok"}
    k = ds["planet_load_sharing.static_torque"].values
    assert k[0] == pytest.approx(1.0, abs=1e-9) and k[1] > 1.01
    planets = [v for v in ds.data_vars if v.startswith("planet_load_sharing.static_torque.")]
    assert "planet_load_sharing.static_torque.stage_carrier" in planets and len(planets) == 5
    # described as what it is: K_gamma from the position-averaged loads (it was given the
    # peak ratio's text of the static_torque definition, a planetary reviewer)
    from torquesplit.study.outputs import output_definitions

    said, = output_definitions(planets)
    assert "K_gamma" in said and "averaged over the mesh positions" in said
    assert "largest over the mesh positions" not in said
    assert ds["planet_load_sharing.static_torque"].attrs["long_name"].startswith(
        "planet load-sharing factor (largest planet over the mean) (static_torque)")


def test_a_dynamic_study_gives_k_gamma_of_its_definition(lp_file):
    ds = run_study(_study(lp_file, "planetary.0.pin_errors.0.tangential",
                          ["planet_load_sharing.mean_force"], {"cycles": 40}))
    k = ds["planet_load_sharing.mean_force"].values
    assert k[0] == pytest.approx(1.0, abs=1e-6) and k[1] > 1.01


def test_a_generated_element_is_refused_with_the_stage_field(lp_file):
    spec = _study(lp_file, "meshes.stage_sun_planet1.backlash", ["load_sharing.*"],
                  {"cycles": 40})
    with pytest.raises(StudyError, match=r"planetary\.0\.sun_mesh\.backlash"):
        Study(spec).plan()


def test_a_model_object_takes_the_paths_of_its_file(lp_file):
    """A Model read from the file, given to the study in Python, takes the stage's own
    paths as the file does (it took only the generated ones) and gives the same dataset;
    a generated path is refused the same way."""
    import torquesplit

    analysis = {"type": "static", "revolutions": 0.02}
    path = "planetary.0.pin_errors.0.tangential"
    ref = run_study(_study(lp_file, path, ["planet_load_sharing.*"], analysis))
    spec = _study(lp_file, path, ["planet_load_sharing.*"], analysis)
    spec["study"]["model"] = torquesplit.load_model(lp_file)
    got = run_study(spec)
    assert (got["planet_load_sharing.static_torque"].values
            == ref["planet_load_sharing.static_torque"].values).all()
    spec = _study(lp_file, "meshes.stage_sun_planet1.backlash", ["load_sharing.*"],
                  {"cycles": 40})
    spec["study"]["model"] = torquesplit.load_model(lp_file)
    with pytest.raises(StudyError, match=r"planetary\.0\.sun_mesh\.backlash"):
        Study(spec).plan()


def test_pin_errors_vary_where_the_file_leaves_them_out(lp_file):
    """The shipped example gives no pin_errors: a study writes the list out (an empty
    table per planet, nothing changed) and varies one planet's, with the same K_gamma as
    the file that lists them; a pattern ranges over every planet (it was refused:
    "'planetary.0.pin_errors' does not exist in the model")."""
    import torquesplit
    from torquesplit.model.overrides import read_raw
    from torquesplit.study.paths import expand

    analysis = {"type": "static", "revolutions": 0.02}
    path = "planetary.0.pin_errors.0.tangential"
    ref = run_study(_study(lp_file, path, ["planet_load_sharing.*"], analysis))
    got = run_study(_study(torquesplit.example_path("lin_parker1999_planetary"), path,
                           ["planet_load_sharing.*"], analysis))
    k = got["planet_load_sharing.static_torque"].values
    assert k[1] > 1.01 and (k == ref["planet_load_sharing.static_torque"].values).all()
    raw = read_raw(torquesplit.example_path("lin_parker1999_planetary"))
    assert expand("planetary.0.pin_errors.*.radial", raw, "here") == [
        f"planetary.0.pin_errors.{i}.radial" for i in range(4)]
    assert raw["planetary"][0]["pin_errors"] == [{}, {}, {}, {}]



def test_a_static_study_gives_the_peak_instantaneous_ratio_beside_k_gamma(tmp_path):
    """The quasi-static peak of the planets' instantaneous load ratio (Mo et al. 2017, not
    K_gamma), which `static` prints beside K_gamma, is a study output too: per stage and
    per planet, the largest N F_i / sum F over the positions of the sweep.  On sequentially
    phased planets (25/29/83) it differs from K_gamma even without errors; a run (dynamic)
    study has no such output."""
    import tomllib

    from planetary_models import three_planet_toml

    from torquesplit.quasistatic import quasi_static_load_sharing
    from torquesplit.study.outputs import output_definitions

    text = three_planet_toml("p3seq", teeth=(25, 29, 83), face_width="50 mm",
                             floating_sun=False, mesh='{method = "iso6336"}',
                             damping_ratio=None)
    raw = tomllib.loads(text)
    raw["planetary"][0]["pin_errors"] = [{"tangential": "0 um"}, {}, {}]
    model = tmp_path / "seq.toml"
    model.write_text(tomli_w.dumps(raw), encoding="utf-8")
    path = "planetary.0.pin_errors.0.tangential"
    ds = run_study(_study(model, path, ["planet_*"], {"type": "static"}))
    assert set(ds["status"].values) == {"ok"}
    peak = ds["planet_peak_instantaneous_ratio"].values
    names = [v for v in ds.data_vars if v.startswith("planet_peak_instantaneous_ratio.")]
    assert len(names) == 4 and "planet_peak_instantaneous_ratio.st_planet2" in names
    assert "not K_gamma" in ds["planet_peak_instantaneous_ratio"].attrs["long_name"]
    said, = output_definitions(["planet_peak_instantaneous_ratio"])
    assert "Mo et al. 2017" in said
    # K_gamma 1 without errors, the peak ratio not (the phased stiffness cycles)
    assert ds["planet_load_sharing.static_torque"].values[0] == pytest.approx(1.0, abs=1e-5)
    assert peak[0] > 1.05
    # by hand from the quasi-static sweep of the second case (10 um on planet 1)
    raw["planetary"][0]["pin_errors"][0]["tangential"] = "10 um"
    qs = quasi_static_load_sharing(raw)
    f = qs.mesh_forces()
    cols = [[qs.mesh_names.index(f"st_{m}_planet{i}") for i in range(1, 4)]
            for m in ("sun", "ring")]
    by_hand = max(np.max(3 * f[:, c] / f[:, c].sum(axis=1, keepdims=True)) for c in cols)
    assert peak[1] == pytest.approx(by_hand, rel=1e-12)
    p2 = max(np.max(3 * f[:, c[1]] / f[:, c].sum(axis=1)) for c in cols)
    assert ds["planet_peak_instantaneous_ratio.st_planet2"].values[1] == pytest.approx(
        p2, rel=1e-12)
    with pytest.raises(StudyError, match="planet_peak_instantaneous_ratio"):
        Study(_study(model, path, ["planet_peak_instantaneous_ratio"], {"cycles": 40})).plan()


def test_a_one_path_parameter_takes_its_path_as_name_and_planet_names_read_short(lp_file):
    """'paths = [one path]' was refused for want of a name, which the docs say defaults to
    the path; the planet factors' family is 'planet_load_sharing.<definition>' with the
    members 'system', '<carrier>', '<planet>' (the figure's legend read
    'static_torque = static_torque.stage_carrier = ...' and squeezed the axes, a
    reviewer), and the definitions line says what a planet's column is."""
    from torquesplit.study.outputs import family, output_definitions, output_long_name

    data = _study(lp_file, "planetary.0.pin_errors.0.tangential",
                  ["planet_load_sharing.*"], {"type": "static", "revolutions": 0.02})
    p = data["grid"]["parameters"][0]
    p["paths"] = [p.pop("path")]
    plan = Study(data).plan()
    assert plan.design.parameters[0].name == "planetary.0.pin_errors.0.tangential"
    assert family("planet_load_sharing.static_torque.stage_planet2") == (
        "planet_load_sharing.static_torque", "stage_planet2")
    assert family("planet_load_sharing.mean_force") == ("planet_load_sharing.mean_force",
                                                        "system")
    assert output_long_name("planet_load_sharing.static_torque.stage_planet2").endswith(
        "(static_torque), stage_planet2")
    said, = output_definitions(["planet_load_sharing.static_torque.stage_planet2"])
    assert ".<planet>: that planet's own load over the mean" in said
