"""Two meshes joining the same two gears double the mesh: said (a reviewer's model was
accepted silently)."""

import tomllib
import warnings

import torquesplit
from test_friction_drift import PAIR


def test_a_second_mesh_on_the_same_gears_is_said():
    text = PAIR.replace("friction = { model = \"constant\", coefficient = 0.1 }\n", "")
    twice = text + '\n[meshes.m2]\ngears = ["wheel", "pinion"]\nstiffness = "4e8 N/m"\n'
    for source, expected in ((text, 0), (twice, 1)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            torquesplit.load_model(tomllib.loads(source))
        said = [str(w.message) for w in caught if "joins the same gears" in str(w.message)]
        assert len(said) == expected, said
    assert said[0].startswith("meshes.m2: joins the same gears as meshes.m")
