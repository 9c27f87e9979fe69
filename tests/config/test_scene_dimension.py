"""The dimension of a scene comes from its body, the model says the constitution
(vemkit.config.dimension, docs/reference/files.md): the defaults by dimension, the refusals, and a
mesh file's dimension read from its header (vemkit.config.mesh_file_header.mesh_file_dimension)."""

import os
from pathlib import Path

import pytest
import yaml

from vemkit.config.dimension import MODELS_BY_DIMENSION, default_model
from vemkit.config.mesh_file_header import mesh_file_dimension
from vemkit.config.scene import SceneError, load_scene, scene_from_dict

BOX = {"box": [[0, 0, 0], [1, 1, 0.5]]}
EXTRUDE = {"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["s", "e", "n", "w"], "extrude": {"depth": 0.5}}


def scene(domain=None, model=None, **extra):
    data = {
        "material": {"E": 1.0, "nu": 0.3},
        "boundary": {"dirichlet": ["bottom" if domain in (None, "unit_square") or "box" in domain else "s"]},
        "discretization": {"mesh": {"family": "hex" if domain == BOX else "square", "n": 2}},
        **extra,
    }
    if domain is not None:
        data["domain"] = domain
    if model is not None:
        data["model"] = model
    return data


def test_the_defaults_by_dimension_are_the_schemas():
    assert default_model(2) == "plane_stress" and default_model(3) == "3d"
    assert MODELS_BY_DIMENSION == {2: ("plane_stress", "plane_strain"), 3: ("3d",)}


@pytest.mark.parametrize("domain", [BOX, EXTRUDE], ids=["box", "extrude"])
def test_a_3d_body_is_3d_with_or_without_model(domain):
    implicit, explicit = scene_from_dict(scene(domain)), scene_from_dict(scene(domain, "3d"))
    assert implicit.dimension == explicit.dimension == 3 and implicit.model == "3d"
    assert implicit == explicit and implicit.to_yaml() == explicit.to_yaml()
    assert implicit.lame() == explicit.lame() and len(implicit.body_force) == 3


@pytest.mark.parametrize("model", [None, "plane_stress", "plane_strain"])
def test_a_2d_body_keeps_its_model_and_default(model):
    s = scene_from_dict(scene(None, model))
    assert s.dimension == 2 and s.model == (model or "plane_stress")
    assert list(s.data) == list(scene_from_dict(scene(None, "plane_stress")).data)  # the key order of before


@pytest.mark.parametrize(
    ("domain", "model", "words"),
    [
        (
            BOX,
            "plane_strain",
            "domain.box is 3D; the models of a 3D body: 3d (the default); drop model or set model: 3d",
        ),
        (EXTRUDE, "plane_stress", "domain.extrude is 3D"),
        (
            "unit_square",
            "3d",
            "domain unit_square is 2D; the models of a 2D body: plane_stress (the default), plane_strain",
        ),
        (None, "3d", "domain unit_square is 2D"),
    ],
)
def test_a_model_that_does_not_fit_the_body_is_refused(domain, model, words):
    with pytest.raises(SceneError, match="does not fit the body") as error:
        scene_from_dict(scene(domain, model))
    assert str(error.value).startswith(f"model = {model!r} does not fit the body: ") and words in str(error.value)
    assert error.value.key == "model" and "\n" not in str(error.value)


def test_set_model_and_a_body_force_component_on_a_box_without_model():
    s = scene_from_dict(scene(BOX), ["body_force[2]=-1"])
    assert s.data["body_force"] == [0.0, 0.0, -1.0] and s.model == "3d"
    with pytest.raises(SceneError, match="model = 'plane_stress' does not fit the body"):
        scene_from_dict(scene(BOX), ["model=plane_stress"])


def test_the_nu_message_names_the_3d_model_on_a_box_without_model():
    with pytest.raises(SceneError, match=r"Poisson ratio of the 3D model"):
        scene_from_dict(scene(BOX, material={"E": 1.0, "nu": 0.5}))


def test_mesh_file_dimension_says_none_when_the_file_does_not(tmp_path):
    assert mesh_file_dimension(tmp_path / "missing.msh") is None
    assert mesh_file_dimension(tmp_path / "mesh.vtk") is None
    (tmp_path / "garbage.msh").write_text("not a mesh\n")
    assert mesh_file_dimension(tmp_path / "garbage.msh") is None
    (tmp_path / "garbage.nc").write_bytes(b"\x00" * 64)
    assert mesh_file_dimension(tmp_path / "garbage.nc") is None
    os.mkfifo(tmp_path / "fifo.msh")
    assert mesh_file_dimension(tmp_path / "fifo.msh") is None  # never blocks on a FIFO


def _gmsh(path, version, dimension, binary=False, volume_group=False):
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("body")
        if dimension == 3:
            gmsh.model.occ.addBox(0, 0, 0, 1, 1, 0.5)
        else:
            gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
        gmsh.model.occ.synchronize()
        if volume_group:
            gmsh.model.setPhysicalName(dimension, gmsh.model.addPhysicalGroup(dimension, [1]), "body")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(dimension)
        gmsh.option.setNumber("Mesh.Binary", int(binary))
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("dimension", [2, 3])
@pytest.mark.parametrize(
    ("version", "binary", "named"),
    [(4.1, False, False), (4.1, True, False), (2.2, False, False), (2.2, True, True)],
    ids=["4-text", "4-binary", "2-text", "2-binary-named"],
)
def test_mesh_file_dimension_of_gmsh_files(tmp_path, dimension, version, binary, named):
    _gmsh(tmp_path / "m.msh", version, dimension, binary, named)
    says = dimension if not (binary and version < 4) or dimension == 3 else None  # its physical volume
    assert mesh_file_dimension(tmp_path / "m.msh") == says


def test_a_binary_gmsh_2_file_without_a_physical_volume_does_not_say(tmp_path):
    _gmsh(tmp_path / "m.msh", 2.2, 3, binary=True)
    assert mesh_file_dimension(tmp_path / "m.msh") is None


ROOT = Path(__file__).resolve().parents[2]
SHIPPED = sorted(
    p
    for folder in ("config/scenes", "benchmarks")
    for p in (ROOT / folder).rglob("*.yaml")
    if "material:" in p.read_text()
)


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_shipped_scene_keeps_its_dimension_and_model_and_reads_the_same_without_model(path):
    data = yaml.safe_load(path.read_text())
    if "file" in data["discretization"]["mesh"]:  # the mesh file is made by a benchmark
        pytest.skip("a mesh file made by its benchmark")
    s = load_scene(path)
    assert s.dimension == (3 if data.get("model") == "3d" else 2)
    assert s.model == data.get("model", "plane_stress")
    data.pop("model", None)
    assert scene_from_dict(data, source=str(path)) == (
        s if s.dimension == 3 else s.with_overrides(["model=plane_stress"])
    )
