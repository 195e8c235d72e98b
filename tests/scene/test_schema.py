"""Scene validation: messages name the key path, the value and what is allowed."""
import pytest

from ngcontact.scene import loader as scene
from ngcontact.errors import SceneError


def base():
    return {"kind": "manufactured",
            "materials": {"steel": {"E": 210e9, "nu": 0.3}},
            "manufactured": {"body": "steel"}}


def message(data):
    with pytest.raises(SceneError) as info:
        scene.from_dict(data)
    return str(info.value)


def test_valid_scene_round_trips():
    sc = scene.from_dict(base())
    assert sc.materials["steel"].E == 210e9
    assert scene.as_dict(sc)["manufactured"]["orders"] == [1, 2, 3]
    assert scene.effects(sc) == ("elasticity",)


@pytest.mark.parametrize("edit, expected", [
    (lambda d: d["materials"]["steel"].update(nu=0.5), "materials.steel.nu = 0.5: must lie in (-1, 0.5)"),
    (lambda d: d["materials"]["steel"].update(E=-1.0), "materials.steel.E = -1.0: must be > 0"),
    (lambda d: d["materials"]["steel"].update(E=float("inf")), "materials.steel.E = inf: must be a finite number"),
    (lambda d: d["materials"]["steel"].update(E=True), "materials.steel.E = True: must be a number"),
    (lambda d: d.update(kind="celll"), "kind = 'celll': must be one of"),
    (lambda d: d["manufactured"].update(ordres=[1]),
     "manufactured.ordres = [1]: unknown key; allowed keys here are body, levels, max_elements, maxh, orders, rate_tolerance, second_body, setting"),
    (lambda d: d["manufactured"].update(orders=[0, 1]), "manufactured.orders = [0, 1]: must lie in [1, 10]"),
    (lambda d: d["manufactured"].update(body="bone"),
     "manufactured.body = 'bone': must name a material defined under [materials]: steel"),
    (lambda d: d["materials"]["steel"].pop("nu"), "materials.steel.nu = <missing>: required"),
    (lambda d: d["manufactured"].update(second_body="steel"),
     "manufactured.second_body = 'steel': not used by setting = 'plane_strain'; remove it"),
])
def test_invalid_scenes_name_key_value_and_rule(edit, expected):
    data = base()
    edit(data)
    assert message(data).startswith(expected)


def test_anisotropic_material_must_be_positive_definite():
    data = base()
    data["materials"]["steel"] = {"C": [[1.0 if i == j else 0.0 for j in range(6)] for i in range(5)] + [[0.0] * 6]}
    assert message(data).startswith("materials.steel.C = ")
    assert "positive definite" in message(data)
