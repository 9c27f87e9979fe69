"""Scene files (docs/reference/files.md): the paper scene, defaults, overrides and one-line rejections."""

import copy
import json
import pickle
from importlib.resources import files
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import yaml

from vemkit.config.scene import Scene, load_scene, scene_from_dict, scene_from_yaml, scene_schema
from vemkit.exceptions import InputError, SceneError

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"

# docs/reference/files.md, "minimal form of the paper scene", verbatim.
SPEC_PAPER_SCENE = {
    "name": "paper",
    "domain": "unit_square",
    "material": {"E": 2000.0, "nu": 0.4},
    "body_force": [0.0, 0.0],
    "boundary": {
        "dirichlet": ["right"],
        "neumann": {"left": {"traction": ["200*(5-y)", "-200"]}, "top": {"traction": [0.0, 0.0]}},
        "contact": ["bottom"],
    },
    "contact": {"gap": 0.1, "normal": {"k": 10.0, "m": 1.0}, "friction": {"k": 450.0, "m": 0.0}},
    "discretization": {
        "mesh": {"family": "square", "n": 16},
        "stabilization": "dofi-2mu",
        "contact_quadrature": "nodal",
    },
    "solver": {"method": "ssn", "tol": 1.0e-10},
}


@pytest.fixture(scope="module")
def paper():
    return load_scene(PAPER)


def rejection(data=None, overrides=()):
    """The one-line message of the SceneError raised for ``data`` (default: the paper) + overrides."""
    with pytest.raises(SceneError) as caught:
        scene_from_dict(SPEC_PAPER_SCENE if data is None else data, overrides)
    message = str(caught.value)
    assert "\n" not in message and message.strip() == message
    assert isinstance(caught.value, ValueError)
    return message


def test_paper_file_is_the_spec_scene():
    assert yaml.safe_load(PAPER.read_text()) == SPEC_PAPER_SCENE


def test_paper_scene_has_the_paper_numbers(paper):
    assert paper.name == "paper" and paper.domain == "unit_square"
    assert paper.E == 2000.0 and paper.nu == 0.4
    lambda_star, mu = paper.lame()
    assert lambda_star == pytest.approx(2000.0 * 0.4 / (1.0 - 0.16))
    assert mu == pytest.approx(2000.0 / 2.8)
    assert paper.dirichlet_sides == ("right",)
    assert paper.neumann_sides == ("left", "top")
    assert paper.contact_sides == ("bottom",)
    assert paper.sides == ("left", "right", "bottom", "top")
    assert paper.normal_compliance == (10.0, 1.0)
    assert paper.friction_bound.k == 450.0 and paper.friction_bound.m == 0.0
    assert paper.gap_expression.is_constant and paper.gap_expression.constant_value == 0.1
    assert paper.mesh_options == {"family": "square", "n": 16}
    assert isinstance(paper.mesh_options["n"], int)
    assert paper.stabilization == "dofi-2mu" and paper.contact_quadrature == "nodal"
    assert paper.solver_options == {
        "method": "ssn",
        "tol": 1e-10,
        "max_iterations": None,
        "linear": "auto",
        "rho": None,
        "eps_u": None,
        "eps_lambda": None,
        "stop": "either",
        "time_budget": None,
    }


def test_paper_loads_and_tractions_evaluate_vectorised(paper):
    f_x, f_y = paper.traction("left")
    y = np.linspace(0.0, 1.0, 5)
    np.testing.assert_allclose(f_x(np.zeros_like(y), y), 200.0 * (5.0 - y))
    np.testing.assert_array_equal(f_y(np.zeros_like(y), y), np.full(5, -200.0))
    top = paper.traction("top")
    assert all(c.is_constant and c.constant_value == 0.0 for c in top)
    assert [c(0.5, 0.5) for c in paper.body_force] == [0.0, 0.0]
    with pytest.raises(KeyError):
        paper.traction("bottom")


def test_schema_ships_as_package_data_and_is_strict():
    path = files("vemkit.config") / "schemas" / "scene.schema.json"
    assert path.is_file()
    schema = scene_schema()
    jsonschema.Draft202012Validator.check_schema(schema)

    def objects(node):
        if isinstance(node, dict):
            if node.get("type") == "object":
                yield node
            for child in node.values():
                yield from objects(child)
        elif isinstance(node, list):
            for child in node:
                yield from objects(child)

    found = list(objects(schema))
    assert len(found) > 8
    # every mapping is closed: fixed keys (additionalProperties false), or a map from side names
    # (propertyNames) whose unknown sides the semantic checks refuse
    assert all(node.get("additionalProperties") is False or "propertyNames" in node for node in found)


def test_defaults_come_from_the_schema_and_the_filled_scene_validates(paper):
    minimal = copy.deepcopy(SPEC_PAPER_SCENE)
    for key in ("name", "domain", "body_force", "solver"):
        del minimal[key]
    del minimal["discretization"]["stabilization"], minimal["contact"]["gap"]
    scene = scene_from_dict(minimal)
    data = scene.data
    schema = scene_schema()
    assert data["name"] == schema["properties"]["name"]["default"]
    assert data["domain"] == "unit_square" and data["body_force"] == [0.0, 0.0]
    assert data["discretization"]["stabilization"] == "dofi-2mu"
    assert data["contact"]["gap"] == 0.0
    assert data["solver"]["method"] == "ssn" and data["solver"]["tol"] == 1e-10
    assert data["solver"]["stop"] == "either" and data["solver"]["rho"] is None
    jsonschema.Draft202012Validator(schema).validate(data)
    jsonschema.Draft202012Validator(schema).validate(paper.data)


def test_to_yaml_round_trips(paper):
    text = paper.to_yaml()
    assert yaml.safe_load(text) == paper.data
    assert scene_from_yaml(text) == paper
    assert pickle.loads(pickle.dumps(paper)) == paper
    odd = paper.with_overrides(["contact.gap=1e-2*(1+x)", "body_force=['1e5', 0]"])
    again = scene_from_yaml(odd.to_yaml())
    assert again == odd and again.data["body_force"][0] == "1e5"
    assert yaml.safe_load(odd.to_yaml()) == odd.data


def test_scene_is_immutable_and_data_is_a_copy(paper):
    with pytest.raises(AttributeError):
        paper.E = 1.0
    paper.data["material"]["E"] = -1.0
    assert paper.E == 2000.0


def test_overrides_change_the_scene(paper):
    scene = paper.with_overrides(
        [
            "solver.method=uzawa",
            "discretization.mesh.n=32",
            "contact.friction.k=0",
            "solver.tol=1e-8",
            "boundary.neumann.left.traction[1]=-100*x",
            "discretization.mesh.family=voronoi",
            "discretization.mesh.seed=7",
        ]
    )
    assert scene.solver_options["method"] == "uzawa" and scene.solver_options["tol"] == 1e-8
    assert scene.mesh_options == {"family": "voronoi", "n": 32, "seed": 7}
    assert scene.friction_bound.k == 0.0
    assert scene.traction("left")[1](np.array([0.5]), 0.0)[0] == -50.0
    assert load_scene(PAPER, ["solver.method=uzawa"]).solver_options["method"] == "uzawa"
    assert paper.solver_options["method"] == "ssn"  # the original is untouched
    assert scene_from_dict(SPEC_PAPER_SCENE, "solver.max_iterations=5").solver_options["max_iterations"] == 5


@pytest.mark.parametrize(
    "override, named",
    [
        ("solver.foo=1", "solver.foo"),
        ("foo=1", "foo"),
        ("material.G=1", "material.G"),
        ("contact.frction.k=1", "contact.frction"),
        ("material.E.x=1", "material.E"),
        ("body_force[2]=1", "body_force"),
        ("solver.method", "solver.method"),
        ("=3", "=3"),
        ("solver.tol=[1,", "solver.tol"),
    ],
)
def test_unknown_or_malformed_overrides_are_rejected(override, named):
    message = rejection(overrides=[override])
    assert message.startswith(f"--set {override}")
    assert named in message


def with_change(path, value):
    data = copy.deepcopy(SPEC_PAPER_SCENE)
    node = data
    for part in path[:-1]:
        node = node[part]
    if value is KeyError:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return data


@pytest.mark.parametrize(
    "override, named, says",
    [
        ("contact.normal.k=-1", "contact.normal.k = -1", ">= 0"),
        ("contact.normal.m=-1", "contact.normal.m = -1", ">= 0"),
        ("contact.friction.k=-450", "contact.friction.k = -450", ">= 0"),
        ("contact.friction.m=-0.5", "contact.friction.m = -0.5", ">= 0"),
        ("material.E=0", "material.E = 0", ">= 1e-12"),
        ("material.E=-2000", "material.E = -2000", ">= 1e-12"),
        ("material.E=abc", "material.E = 'abc'", "must be a number"),
        ("material.E=true", "material.E = true", "must be a number"),
        ("material.E=.nan", "material.E = nan", "finite"),
        ("material.nu=0.5", "material.nu = 0.5", "< 0.5"),
        ("material.nu=0.7", "material.nu = 0.7", "< 0.5"),
        ("material.nu=-1", "material.nu = -1", ">= -0.999"),
        ("discretization.mesh.n=0", "discretization.mesh.n = 0", ">= 1"),
        ("discretization.mesh.n=2.5", "discretization.mesh.n = 2.5", "integer"),
        ("discretization.mesh.n=sixteen", "discretization.mesh.n = 'sixteen'", "integer"),
        ("discretization.mesh.family=hexagon", "discretization.mesh.family", "square"),
        ("discretization.stabilization=none", "discretization.stabilization", "dofi-2mu"),
        ("solver.method=newton", "solver.method", "ssn, uzawa"),
        ("solver.tol=0", "solver.tol = 0", ">= 1e-15"),
        ("solver.max_iterations=0", "solver.max_iterations = 0", ">= 1"),
        ("solver.rho=-1", "solver.rho = -1", "> 0"),
        ("body_force=[0]", "body_force", "2"),
        ("boundary.dirichlet=[front]", "boundary.dirichlet[0] = 'front'", "unknown boundary name"),
        ("boundary.contact=[bottom, bottom]", "boundary.contact", "twice"),
        ("boundary.contact=[bottom, left]", "'left'", "both neumann and contact"),
        ("boundary.contact=[right]", "'right'", "both dirichlet and contact"),
        (
            "boundary.dirichlet=[]",
            "boundary.dirichlet",
            "no Dirichlet part: the body is not held; add boundary.dirichlet: [right]",
        ),
        ("boundary.neumann.left.traction[0]=200*(5-", "boundary.neumann.left.traction[0]", "not a valid expression"),
        ("boundary.neumann.left.traction[0]=__import__('os')", "boundary.neumann.left.traction[0]", "'__import__'"),
        ("boundary.neumann.left.traction[0]=x.real", "boundary.neumann.left.traction[0]", "x.real"),
        ("boundary.neumann.left.traction[0]=open('f')", "boundary.neumann.left.traction[0]", "'open'"),
        ("body_force[0]=lambda: 1", "body_force[0]", "lambda"),
        ("body_force[1]=[1,2]", "body_force[1]", "must be a number or a string"),
        ("body_force[1]='[1,2]'", "body_force[1]", "a list"),
        ("contact.gap=y if x else 1", "contact.gap", "conditional"),
        ("boundary.neumann.left.traction[1]=1e400*x", "boundary.neumann.left.traction[1]", "finite"),
        ("contact.gap=1/x", "contact.gap", "finite"),
        ("contact.gap=-0.1", "contact.gap = -0.1", ">= 0"),
        ("contact.gap=0.05-x", "contact.gap", "g_a must be >= 0"),
    ],
)
def test_rejections_are_one_line_and_name_the_key(override, named, says):
    message = rejection(overrides=[override])
    assert named in message
    assert says in message


@pytest.mark.parametrize(
    "path, value, named",
    [
        (("colour",), "red", "colour: unknown key"),
        (("material", "G"), 1.0, "material.G: unknown key"),
        (("contact", "normal", "exponent"), 1.0, "contact.normal.exponent: unknown key"),
        (("discretization", "mesh", "size"), 0.1, "discretization.mesh.size: unknown key"),
        (("boundary", "neumann", "front"), {"traction": [0, 0]}, "unknown boundary name 'front'"),
        (("boundary", "dirichlet"), KeyError, "no Dirichlet part"),
        (("material", "E"), KeyError, "material.E is missing"),
        (("discretization", "mesh"), KeyError, "discretization.mesh is missing"),
        (("contact", "friction"), KeyError, "contact.friction is missing"),
        (("contact",), KeyError, "contact is missing: boundary.contact lists bottom"),
        (("material", "E"), True, "material.E = true: must be a number"),
        (("material", "E"), "2000", "material.E = '2000': must be a number"),
        (("discretization", "mesh", "n"), 16.5, "discretization.mesh.n = 16.5"),
    ],
)
def test_scene_data_rejections(path, value, named):
    assert named in rejection(with_change(path, value))


def test_integral_floats_are_accepted_as_integers():
    scene = scene_from_dict(with_change(("discretization", "mesh", "n"), 8.0))
    assert scene.mesh_options["n"] == 8 and isinstance(scene.mesh_options["n"], int)


def test_scene_without_contact():
    data = with_change(("contact",), KeyError)
    data["boundary"]["contact"] = []
    scene = scene_from_dict(data)
    assert scene.contact_sides == () and not scene.has_contact
    assert scene.gap_expression is None and scene.normal_compliance is None
    assert scene.friction_bound is None


def test_file_problems_are_one_line(tmp_path):
    missing = tmp_path / "nope.yaml"
    with pytest.raises(SceneError, match=r"nope\.yaml: scene file not found$"):
        load_scene(missing)
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: paper\nmaterial: {E: 1, nu: 0.3\nsolver: {}\n")
    with pytest.raises(SceneError) as caught:
        load_scene(broken)
    assert "\n" not in str(caught.value)
    assert str(caught.value).startswith(f"{broken}:3: YAML syntax error")
    twice = tmp_path / "twice.yaml"
    twice.write_text(PAPER.read_text() + "material: {E: 1.0, nu: 0.3}\n")
    with pytest.raises(SceneError, match=r"twice\.yaml:\d+: .*duplicate key 'material'"):
        load_scene(twice)
    empty = tmp_path / "empty.yaml"
    empty.write_text("# nothing\n")
    with pytest.raises(SceneError, match="empty"):
        load_scene(empty)
    listing = tmp_path / "list.yaml"
    listing.write_text("- 1\n- 2\n")
    with pytest.raises(SceneError, match="mapping"):
        load_scene(listing)
    with pytest.raises(SceneError, match="cannot read"):
        load_scene(tmp_path)


def test_scientific_notation_without_a_dot_is_a_number(tmp_path):
    text = PAPER.read_text().replace("tol: 1.0e-10", "tol: 1e-9").replace("E: 2000.0", "E: 2e3")
    scene = scene_from_yaml(text)
    assert scene.solver_options["tol"] == 1e-9 and scene.E == 2000.0


def test_message_of_an_out_of_range_poisson_ratio():
    assert rejection(overrides=["material.nu=0.7"]) == (
        "material.nu = 0.7: must be < 0.5 (Poisson ratio of plane stress); fix the scene or --set material.nu=..."
    )


def test_first_problem_in_file_order_is_reported():
    data = with_change(("material", "E"), -1.0)
    data["solver"]["method"] = "newton"
    assert rejection(data).startswith("material.E = -1.0")
    assert Scene is type(scene_from_dict(SPEC_PAPER_SCENE))
    assert json.dumps(scene_from_dict(SPEC_PAPER_SCENE).data)  # plain data only


def test_an_unknown_side_in_an_override_names_the_sides_of_the_domain():
    """Side names belong to the domain (docs/reference/files.md), so an override cannot know them: the scene check
    refuses the unknown side and lists the valid ones."""
    message = rejection(overrides=["boundary.neumann.front={traction: [0, 0]}"])
    assert "'front'" in message and "left, right, bottom, top" in message


# -- any domain (docs/reference/files.md) -------------------------------------------------------------------------
def _plate(**extra):
    data = yaml.safe_load(PAPER.read_text())
    data["domain"] = {
        "polygon": [[0, 0], [4, 0], [4, 2], [0, 2]],
        "sides": ["base", "right", "top", "left"],
        "holes": [{"circle": [2.0, 1.0, 0.4], "side": "hole"}],
    }
    data["boundary"] = {"dirichlet": ["left"], "neumann": {"right": {"traction": [1.0, 0.0]}}, "contact": ["base"]}
    data.update(extra)
    return data


def test_a_scene_describes_its_own_body_and_its_sides():
    scene = scene_from_dict(_plate())
    assert scene.sides == ("base", "right", "top", "left", "hole")
    assert scene.neumann_sides == ("right",) and scene.contact_sides == ("base",)
    with pytest.raises(
        SceneError,
        match=r"boundary.neumann.front: unknown boundary name 'front'; the domain has "
        r"sides base, right, top, left, hole",
    ):
        scene_from_dict(_plate(boundary={"dirichlet": ["left"], "neumann": {"front": {"traction": [0, 0]}}}))


@pytest.mark.parametrize(
    "domain, says",
    [
        ({"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["a", "b", "c"]}, "domain.sides"),
        ({"polygon": [[0, 0], [0, 1], [1, 1], [1, 0]], "sides": ["a", "b", "c", "d"]}, "clockwise"),
        (
            {
                "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
                "sides": ["a", "b", "c", "d"],
                "holes": [{"circle": [3.0, 3.0, 0.5], "side": "h"}],
            },
            "domain.holes[0]",
        ),
        (
            {
                "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
                "sides": ["a", "b", "c", "d"],
                "holes": [{"circle": [0.5, 0.5, 0.0], "side": "h"}],
            },
            "domain.holes[0]",
        ),
    ],
)
def test_a_broken_body_is_refused_in_one_line(domain, says):
    data = yaml.safe_load(PAPER.read_text())
    data["domain"] = domain
    data["boundary"] = {"dirichlet": ["a"], "neumann": {}, "contact": []}
    data.pop("contact")
    with pytest.raises(InputError) as caught:
        scene_from_dict(data)
    assert says in str(caught.value) and "\n" not in str(caught.value)


def test_a_scene_with_a_foundation_reads_back_and_takes_overrides():
    """contact.foundation defines the gap: no default gap is filled in beside it, so the scene's own
    YAML (stored in every solution file) and with_overrides give the same scene again."""
    from pathlib import Path

    from vemkit.config.scene import load_scene, scene_from_yaml

    hertz = load_scene(Path(__file__).resolve().parents[2] / "config" / "scenes" / "hertz.yaml")
    assert "gap" not in hertz.data["contact"] and hertz.foundation is not None
    assert scene_from_yaml(hertz.to_yaml()) == hertz
    coarse = hertz.with_overrides(["discretization.mesh.h=0.2"])
    assert coarse.mesh_options["h"] == 0.2 and coarse.foundation == hertz.foundation
