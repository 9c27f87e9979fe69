"""The Snakemake workflow's configuration checked when the Snakefile loads it, before any job (also in
``snakemake -n``): what the JSON schemas of ``workflow/schemas/`` cannot say.

- cross-field constraints: every mesh label is defined, every level below the reference,
  ``three_d.figure_level`` an index of every manufactured case's levels, ...;
- every value the workflow forwards into a scene (``solver``, ``overrides``, a sweep's grid values,
  the robustness matrix's solvers, the 3D studies' solver sections, mesh family options) goes through
  the scene's own validation, on the scene it is forwarded to, and a refusal names the CONFIG key;
- :func:`config_source`: which of the layered files (config/*.yaml, ``--configfile``, ``--config``)
  set a key, so that the one-line message names the file to fix.

Every failure is a :class:`vemkit.exceptions.WorkflowConfigError` whose ``path`` is the config key.
Imports from vemkit: ``exceptions``, ``config`` (scenes, the scene schema), ``studies.sweep_dimensions``.
"""

from __future__ import annotations

import copy
from pathlib import Path

import jsonschema

from vemkit.config.overrides import apply_override
from vemkit.config.safe_yaml import parse_yaml, read_user_file
from vemkit.config.scene import scene_from_dict
from vemkit.config.scene_schema import (
    check_finite,
    first_problem,
    schema_error_message,
    schema_root,
    schema_validator,
)
from vemkit.exceptions import InputError, SceneError, WorkflowConfigError
from vemkit.studies.sweep_dimensions import dimension_name

__all__ = ["check_workflow_config", "config_source"]

_FIX = "change the config value"


def _fix(_key) -> str:
    return _FIX


# -- which file set a key ---------------------------------------------------------------------------
def _has(data, path) -> int:
    """How many leading segments of ``path`` ``data`` holds."""
    depth = 0
    for part in path:
        if isinstance(data, dict) and part in data:
            data = data[part]
        elif isinstance(data, list) and isinstance(part, int) and 0 <= part < len(data):
            data = data[part]
        else:
            break
        depth += 1
    return depth


def config_source(path, layers) -> str:
    """The name of the layer that set ``path``: ``layers`` is [(name, data)], lowest priority first
    (the Snakefile's config files, then each ``--configfile``, then ``--config``); Snakemake merges
    mappings key by key, so the last layer holding the key (else the longest part of it) set it."""
    path = tuple(path)
    best, depth = layers[0][0] if layers else "the configuration", 0
    for name, data in layers:
        found = _has(data, path)
        if found and found >= depth:
            best, depth = name, found
    return best


# -- values forwarded into a scene ----------------------------------------------------------------
class _Scenes:
    """Scene files read once; a refusal of a forwarded value names its config key. Only ``solver.*``
    values (no check beyond the schema reads the solver section): the schema alone, else the scene's
    whole validation (expressions, sides, 3D limits)."""

    def __init__(self):
        self._read = {}
        self._passed = set()  # (scene file, overrides) found valid

    def data(self, path_key, scene_path) -> dict:
        """The scene file's plain data, as the jobs read it (the overrides go on top)."""
        if scene_path not in self._read:
            try:
                data = parse_yaml(read_user_file(Path(scene_path)), str(scene_path))
            except InputError as error:
                raise WorkflowConfigError(f"the scene file is refused: {error}", path=path_key) from None
            if not isinstance(data, dict):
                raise WorkflowConfigError(f"{scene_path}: not a scene (a mapping of keys)", path=path_key)
            self._read[scene_path] = data
        return copy.deepcopy(self._read[scene_path])

    @staticmethod
    def refusal(data: dict, overrides, whole: bool) -> str | None:
        """Why the scene ``data`` with ``overrides`` applied is refused (None: it is not)."""
        try:
            for override in overrides:
                apply_override(data, override)
            check_finite(data, [], _fix)
            errors = list(schema_validator().iter_errors(data))
            if errors:
                return schema_error_message(first_problem(errors, data), _fix)
            if whole:
                scene_from_dict(data)  # the checks beyond the schema (expressions, sides, ...)
        except InputError as error:  # SceneError, ExpressionError, MeshError
            return str(error)
        return None

    def check(self, scene_key, scene_path, steps, extra=()) -> None:
        """``steps``: [(config path, override)] in the order the job applies them, after ``extra``
        (overrides checked before); the first one that makes the scene invalid is blamed."""
        base = self.data(scene_key, scene_path)
        extra = list(extra)
        overrides = extra + [o for _, o in steps]
        if not steps or (scene_path, tuple(overrides)) in self._passed:
            return
        whole = not all(o.startswith("solver.") for o in overrides)
        if self.refusal(copy.deepcopy(base), overrides, whole) is None:
            self._passed.add((scene_path, tuple(overrides)))
            return
        problem = self.refusal(copy.deepcopy(base), extra, whole)
        if problem:  # the scene itself (with what was checked before)
            raise WorkflowConfigError(f"the scene file is refused: {scene_path}: {problem}", path=scene_key)
        for i, (path, _) in enumerate(steps):
            problem = self.refusal(copy.deepcopy(base), extra + [o for _, o in steps[: i + 1]], whole)
            if problem:
                raise WorkflowConfigError(f"the scene {scene_path} refuses it: {problem}", path=path)


def _solver_steps(prefix, solver: dict):
    return [((*prefix, key), f"solver.{key}={value}") for key, value in solver.items()]


def _override_steps(prefix, overrides):
    return [((*prefix, i), text) for i, text in enumerate(overrides)]


def _mesh_options(path, family, n, options) -> None:
    """A family's options through the scene schema's discretization.mesh node."""
    root = schema_root()
    node = {**root["properties"]["discretization"]["properties"]["mesh"], "$defs": root["$defs"]}
    data = {"family": family, "n": n, **dict(options or {})}
    try:
        check_finite(data, [], _fix)
    except SceneError as error:
        raise WorkflowConfigError(f"the {family} mesh family refuses {error}", path=(*path, error.key)) from None
    errors = list(jsonschema.Draft202012Validator(node).iter_errors(data))
    if errors:
        first = first_problem(errors, data)
        inner = list(first.absolute_path)
        if first.validator == "additionalProperties":
            inner = [next(k for k in first.instance if k not in node["properties"])]
        where = (*path, *inner[:1]) if inner and inner[0] in (options or {}) else path
        raise WorkflowConfigError(f"the {family} mesh family refuses {schema_error_message(first, _fix)}", path=where)


# -- the paper (config/config.yaml) -----------------------------------------------------------------
def _check_paper(config, scenes: _Scenes) -> None:
    meshes, ref, fig, levels = config["meshes"], config["reference"], config["figures"], sorted(config["levels"])
    used = [(("reference", "mesh"), ref["mesh"]), (("table1", "mesh"), config["table1"]["mesh"])]
    used += [(("convergence", i), label) for i, label in enumerate(config["convergence"])]
    used += [(("figures", "fields", k, "mesh"), v["mesh"]) for k, v in fig["fields"].items()]
    used += [(("figures", k, "mesh"), fig[k]["mesh"]) for k in ("deformed", "contact")]
    for path, label in used:
        if label not in meshes:
            raise WorkflowConfigError(
                f"{label!r} is not a mesh family label; use one of meshes: {', '.join(meshes)}", path=path
            )
    for label, spec in meshes.items():
        _mesh_options(("meshes", label, "options"), spec["family"], levels[0], spec.get("options"))
    for i, n in enumerate(config["levels"]):
        if n >= ref["n"]:
            raise WorkflowConfigError(
                f"{n} >= reference.n = {ref['n']}: errors are measured against the finer "
                "reference; drop the level or refine the reference",
                path=("levels", i),
            )
    at = [(("figures", "fields", k), v) for k, v in fig["fields"].items()]
    for key, spec_at in at + [(("figures", "deformed"), fig["deformed"]), (("figures", "contact"), fig["contact"])]:
        spec = meshes[spec_at["mesh"]]
        delaunay = spec["family"] == "triangle" and spec.get("options", {}).get("kind", "delaunay") == "delaunay"
        if not float(spec_at["n"]).is_integer() and not delaunay:
            raise WorkflowConfigError(
                f"{spec_at['n']}: only the Delaunay triangle family takes a non-integer n; give an integer",
                path=(*key, "n"),
            )
    if ref["n"] not in (2**k for k in range(1, 16)):
        raise WorkflowConfigError(
            f"{ref['n']}: the error measure needs n a power of 2 (nested with the square levels); use 256",
            path=("reference", "n"),
        )
    if meshes[ref["mesh"]]["family"] != "square":
        raise WorkflowConfigError(
            f"{ref['mesh']!r} is a {meshes[ref['mesh']]['family']} family: the error "
            "measure needs a square reference mesh",
            path=("reference", "mesh"),
        )
    steps = _override_steps(("overrides",), config["overrides"]) + _solver_steps(("solver",), config["solver"])
    scenes.check(("scene",), config["scene"], steps)
    from vemkit.studies.solution_order import require_order1

    try:  # valid after the check above
        scene = scene_from_dict(scenes.data(("scene",), config["scene"]), config["overrides"])
    except InputError as error:
        raise WorkflowConfigError(f"the scene file is refused: {config['scene']}: {error}", path=("scene",)) from None
    try:
        require_order1(scene, "the paper workflow (Table 1, convergence)")
    except SceneError as error:
        raise WorkflowConfigError(str(error), path=("overrides",)) from None


# -- the studies (config/sweeps.yaml) ---------------------------------------------------------------
def _check_sweeps(config, scenes: _Scenes) -> None:
    scene, base = config["studies_scene"], _override_steps(("studies_overrides",), config["studies_overrides"])
    scenes.check(("studies_scene",), scene, base)
    base_overrides = [o for _, o in base]
    defaults = config["sweep_defaults"]
    scenes.check(
        ("studies_scene",), scene, _solver_steps(("sweep_defaults", "solver"), defaults["solver"]), base_overrides
    )
    for name, spec in config["sweeps"].items():
        own = _override_steps(("sweeps", name, "overrides"), spec["overrides"])
        solver = _solver_steps(("sweeps", name, "solver"), spec.get("solver", {}))
        scenes.check(("studies_scene",), scene, own + solver, base_overrides)
        fixed = base_overrides + [o for _, o in own + solver]
        for key, values in spec["grid"].items():
            for i, value in enumerate(values):
                scenes.check(("studies_scene",), scene, [(("sweeps", name, "grid", key, i), f"{key}={value}")], fixed)
        dims = [dimension_name(k) for k in spec["grid"]]
        meshed = any(k.startswith("discretization.mesh") for k in spec["grid"])
        for kind, figure in spec["figures"].items():
            used = [((a,), figure[a]) for a in ("x", "y", "hue", "across") if a in figure]
            used += [(("select", dim), dim) for dim in figure.get("select", {})]
            for where, dim in used:
                if dim not in dims:
                    raise WorkflowConfigError(
                        f"{dim!r} is not a dimension of the grid; use one of {', '.join(dims)}",
                        path=("sweeps", name, "figures", kind, *where),
                    )
            plotted = {figure[a] for a in ("x", "y", "hue", "across") if a in figure}
            for dim, value in figure.get("select", {}).items():
                values = next(v for k, v in spec["grid"].items() if dimension_name(k) == dim)
                if dim not in plotted and value not in values:  # the figure holds dim at value
                    raise WorkflowConfigError(
                        f"{value!r} is not a value of the grid's {dim} ({', '.join(map(str, values))}); use one of them",
                        path=("sweeps", name, "figures", kind, "select", dim),
                    )
            if kind == "profiles" and meshed:
                raise WorkflowConfigError(
                    "the grid changes the mesh, so the contact nodes differ between points; drop the profiles figure",
                    path=("sweeps", name, "figures", kind),
                )
    _check_stability_cases(config["stability"], scenes)
    for method, solver in config["stability"]["solvers"].items():
        steps = [(("stability", "solvers", method), f"solver.method={method}")]
        steps += _solver_steps(("stability", "solvers", method), solver)
        scenes.check(("studies_scene",), scene, steps, base_overrides)


def _check_stability_cases(stability: dict, scenes: _Scenes) -> None:
    """The cases are names of the matrix; the base scene a selected case names is in ``scenes`` and readable."""
    from vemkit.studies.robustness import CASES

    cases = stability["cases"]
    names = [case["name"] for case in CASES]
    for i, name in enumerate([] if cases == "all" else cases):
        if name not in names:
            raise WorkflowConfigError(
                f"{name!r} is not a case of the robustness matrix; use all or names of "
                f"vemkit.studies.robustness.CASES, e.g. {', '.join(names[:4])}",
                path=("stability", "cases", i),
            )
    chosen = CASES if cases == "all" else [case for case in CASES if case["name"] in cases]
    for needed in dict.fromkeys(case["scene"] for case in chosen if "scene" in case):
        if needed not in stability["scenes"]:
            raise WorkflowConfigError(
                f"a case of the matrix needs the scene {needed!r}: name its file under stability.scenes",
                path=("stability", "scenes"),
            )
        scenes.data(("stability", "scenes", needed), stability["scenes"][needed])


def _check_tradeoff(config, scenes: _Scenes) -> None:
    tradeoff, ref_n = config["tradeoff"], config["reference"]["n"]
    for i, gain in enumerate(tradeoff["refinement_gain"]):
        for key in ("uniform", "refined"):
            if gain[key] not in tradeoff["families"]:
                raise WorkflowConfigError(
                    f"{gain[key]!r} is not a family of tradeoff.families ({', '.join(tradeoff['families'])})",
                    path=("tradeoff", "refinement_gain", i, key),
                )
    for i, n in enumerate(tradeoff["levels"]):
        if n > ref_n:
            raise WorkflowConfigError(
                f"{n} > reference.n = {ref_n} (config/config.yaml): errors are measured against the finer reference",
                path=("tradeoff", "levels", i),
            )
    for label, spec in tradeoff["families"].items():
        _mesh_options(
            ("tradeoff", "families", label, "options"), spec["family"], min(tradeoff["levels"]), spec.get("options")
        )
    paper = config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()]
    steps = [(("tradeoff", "tolerances", i), f"solver.tol={tol}") for i, tol in enumerate(tradeoff["tolerances"])]
    steps += [
        (("tradeoff", "max_iterations", m), f"solver.max_iterations={v}") for m, v in tradeoff["max_iterations"].items()
    ]
    for step in steps:
        scenes.check(("scene",), config["scene"], [step], paper)


# -- adaptivity and 3D ----------------------------------------------------------------------------
def _check_adaptivity(config, scenes: _Scenes) -> None:
    for study in ("adaptivity_study", "adaptivity3d_study"):
        for label, case in config.get(study, {"scenes": {}})["scenes"].items():
            if Path(case["scene"]).is_file():  # a scene whose file does not exist is skipped (by design)
                scenes.check(
                    (study, "scenes", label, "scene"),
                    case["scene"],
                    _override_steps((study, "scenes", label, "overrides"), case.get("overrides", [])),
                )


def _check_three_d(config, scenes: _Scenes) -> None:
    three_d = config["three_d"]
    solver = _solver_steps(("three_d", "solver"), three_d["solver"])
    level, fewest = three_d["figure_level"], None
    for label, case in three_d["manufactured"].items():
        where = ("three_d", "manufactured", label)
        scenes.data((*where, "scene"), case["scene"])
        scenes.check((*where, "scene"), case["scene"], solver)
        _mesh_options((*where, "options"), case["family"], case["levels"][0], case.get("options"))
        if fewest is None or len(case["levels"]) < len(fewest[1]):
            fewest = (label, case["levels"])
    if fewest and not -len(fewest[1]) <= level < len(fewest[1]):
        count = len(fewest[1])
        raise WorkflowConfigError(
            f"{level} is not an index of the {count} levels of three_d.manufactured.{fewest[0]}; "
            f"use 0..{count - 1} (or -{count}..-1, counted from the finest)",
            path=("three_d", "figure_level"),
        )
    for study in ("lame", "plane_strain", "plane_stress"):
        scenes.check(("three_d", study, "scene"), three_d[study]["scene"], solver)
    for study in ("hertz", "mindlin"):
        spec = config.get(study)
        if spec:
            inherited = solver if study == "hertz" else []
            own = _solver_steps((study, "solver"), spec.get("solver", {}))
            scenes.check((study, "scene"), spec["scene"], inherited + own)
            scenes.check((study, "scene"), spec["scene"], [((study, "nu"), f"material.nu={spec['nu']}")])
    shifts = config.get("mindlin", {}).get("shifts", [])
    for i in range(1, len(shifts)):
        if shifts[i] <= shifts[i - 1]:
            raise WorkflowConfigError(
                f"{shifts[i]} <= the shift before it ({shifts[i - 1]}): the tangential steps "
                "move the platen further each time; list the shifts increasing",
                path=("mindlin", "shifts", i),
            )


def check_workflow_config(config: dict) -> None:
    """Every check beyond the schemas, on the merged, schema-validated and defaults-filled config;
    the first problem is a WorkflowConfigError naming its config key."""
    scenes = _Scenes()
    _check_paper(config, scenes)
    _check_sweeps(config, scenes)
    _check_tradeoff(config, scenes)
    _check_adaptivity(config, scenes)
    _check_three_d(config, scenes)
