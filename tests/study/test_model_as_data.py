"""A study's model from Python: a Model or its data, not only a file or an example name
(a reviewer's model built in Python could not be studied)."""

from __future__ import annotations

import warnings

import numpy as np

import torquesplit
from torquesplit.model.io import model_to_dict


def _study(model):
    return torquesplit.Study({
        "study": {"name": "k", "model": model, "outputs": ["load_sharing.engineering"]},
        "analysis": {"cycles": 20},
        "grid": {"parameters": [{"path": "meshes.m11.damping_ratio", "values": [0.05, 0.1]}]}})


def test_a_model_or_its_data_gives_the_examples_dataset():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model("ji_li_mill_drive")
        ref = _study("ji_li_mill_drive").run(workers=1)["load_sharing.engineering"].values
        for given in (model, model_to_dict(model)):
            study = _study(given)
            assert "model given as data" in repr(study)
            got = study.run(workers=1)["load_sharing.engineering"].values
            np.testing.assert_array_equal(got, ref)
