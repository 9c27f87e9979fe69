# Configuration checks, file names and the targets; no rules here. Every other rule file uses only
# what this file defines (the Snakefile includes it first).
#
# The configuration is Snakemake's own `config`: config/config.yaml (the paper) and
# config/sweeps.yaml (the studies), merged with any `--configfile` / `--config` of the command line.
# Each part is validated against its schema; a key that neither schema knows is an error.
from pathlib import Path

import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from vemkit.studies.sweep_dimensions import dimension_name

#: part of the configuration: (schema, the file that sets its defaults)
CONFIG_PARTS = {
    "paper": ("../schemas/config.schema.yaml", "config/config.yaml"),
    "studies": ("../schemas/sweeps.schema.yaml", "config/sweeps.yaml"),
    "adaptivity": ("../schemas/adaptivity.schema.yaml", "config/adaptivity.yaml"),
    "three_d": ("../schemas/three_d.schema.yaml", "config/three_d.yaml"),
}


def config_error(source, key, problem):
    """The one-line error of a configuration value, naming the key and the file to fix."""
    return WorkflowError(f"invalid workflow configuration: {key or 'top level'}: {problem}; fix {source} "
                         "(or the --configfile / --config that set it)")


def _validated(data, schema, source):
    """Snakemake's validate (fills the defaults in place), its error cut to one line naming the key."""
    import jsonschema

    try:
        validate(data, schema)
    except WorkflowError as error:
        cause = error.__cause__ or error.__context__
        if not isinstance(cause, jsonschema.ValidationError):
            raise
        key = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in cause.absolute_path).lstrip(".")
        raise config_error(f"{source} (schema: workflow/schemas/{Path(schema).name})", key, cause.message) from None


def _validate_config():
    schema_dir = Path(workflow.current_basedir)
    known = set()
    for schema, source in CONFIG_PARTS.values():
        keys = set(yaml.safe_load((schema_dir / schema).read_text(encoding="utf-8"))["properties"])
        part = {k: v for k, v in config.items() if k in keys}
        _validated(part, schema, source)
        config.update(part)
        known |= keys
    unknown = sorted(set(config) - known)
    if unknown:
        raise config_error("config/config.yaml or config/sweeps.yaml", unknown[0], "unknown key")


_validate_config()

MESHES = config["meshes"]
STABS = list(config["stabilizations"])
LEVELS = sorted(config["levels"])
BATCH = config["batch_levels"]
REF = config["reference"]
FIG = config["figures"]
FIG_STAB = FIG["stabilization"]


def _check_config():
    """What the schema cannot say: every label is defined, every level is below the reference."""
    used = [("reference.mesh", REF["mesh"]), ("table1.mesh", config["table1"]["mesh"])]
    used += [(f"convergence[{i}]", label) for i, label in enumerate(config["convergence"])]
    used += [(f"figures.fields.{k}.mesh", v["mesh"]) for k, v in FIG["fields"].items()]
    used += [("figures.deformed.mesh", FIG["deformed"]["mesh"]), ("figures.contact.mesh", FIG["contact"]["mesh"])]
    for key, label in used:
        if label not in MESHES:
            raise WorkflowError(f"config {key} = {label!r}: not a mesh family label; defined in meshes: "
                                f"{', '.join(MESHES)}")
    high = [n for n in LEVELS if n >= REF["n"]]
    if high:
        raise WorkflowError(f"config levels lists {high[0]} >= reference.n = {REF['n']}: errors are measured "
                            "against the finer reference; drop the level or refine the reference")
    fig_meshes = [(f"figures.fields.{k}", v) for k, v in FIG["fields"].items()]
    fig_meshes += [("figures.deformed", FIG["deformed"]), ("figures.contact", FIG["contact"])]
    for key, at in fig_meshes:
        spec = MESHES[at["mesh"]]
        delaunay = spec["family"] == "triangle" and spec.get("options", {}).get("kind", "delaunay") == "delaunay"
        if not float(at["n"]).is_integer() and not delaunay:
            raise WorkflowError(f"config {key}.n = {at['n']}: only the Delaunay triangle family takes a "
                                "non-integer n; give an integer")
    if REF["n"] not in (2 ** k for k in range(1, 16)) or MESHES[REF["mesh"]]["family"] != "square":
        raise WorkflowError(f"config reference = {REF}: the error measure needs a square mesh with n a power "
                            "of 2 (nested with the square levels, docs/reference/mathematics.md)")


def _check_order():
    """The paper workflow measures errors with Pi_1 of vertex values (docs/reference/mathematics.md): k = 1 only."""
    from vemkit.config.scene import load_scene
    from vemkit.exceptions import SceneError
    from vemkit.studies.solution_order import require_order1

    try:
        require_order1(load_scene(config["scene"], config["overrides"]), "the paper workflow (Table 1, convergence)")
    except SceneError as error:
        raise config_error("config/config.yaml (scene, overrides)", "overrides", str(error)) from None


_check_config()
_check_order()


def ntag(n):
    """The n of a file name: 16, or 22.627417 for a non-integer n."""
    n = float(n)
    return str(int(n)) if n.is_integer() else repr(n)


def stabilization_free(label):
    """All-triangle families: the VEM space is P1 and the stabilization vanishes (docs/reference/mathematics.md)."""
    return MESHES[label]["family"] == "triangle"


def solution_stab(label, stab):
    """The solve that gives (label, stab): on triangles one solve serves every stabilization."""
    return FIG_STAB if stabilization_free(label) else stab


def mesh_file(label, n):
    return f"results/meshes/{label}/n{ntag(n)}.nc"


def solution_file(label, stab, n):
    return f"results/solutions/{label}/{solution_stab(label, stab)}/n{ntag(n)}.nc"


def reference_file(stab):
    return solution_file(REF["mesh"], stab, REF["n"])


def errors_file(label):
    return f"results/errors/{label}.json"


def solve_params():
    """Parameters of the solve rules: the scene file, the scene overrides, the family spec."""
    return dict(
        scene=config["scene"],
        overrides=config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()],
        spec=lambda wc: MESHES[wc.label],
    )


def workflow_parameters():
    """The configuration as stored in the netCDF attributes."""
    return {k: config[k] for k in ("solver", "overrides", "stabilizations", "levels", "meshes", "reference",
                                   "table1", "convergence")}


LEVEL_TAGS = [ntag(n) for n in LEVELS]
TABLE_FORMATS = ("md", "csv", "tex")
FIGURE_FORMATS = ("png", "pdf")
FIELD_FIGURES = list(FIG["fields"])

DEFAULT_TARGETS = (
    ["results/table1.nc", "results/convergence.nc"]
    + expand("results/tables/{table}.{ext}", table=["table1", "convergence"], ext=TABLE_FORMATS)
    + expand("results/figures/{fig}.{ext}", fig=FIELD_FIGURES + ["fig6", "contact", "convergence"],
             ext=FIGURE_FORMATS)
)


# -- the studies of config/sweeps.yaml (not in the default target) ---------------------------------
SWEEPS = config["sweeps"]
SWEEP_DEFAULTS = config["sweep_defaults"]
STABILITY = config["stability"]
TRADEOFF = config["tradeoff"]
STUDIES_SOURCE = "config/sweeps.yaml"


def studies_scene():
    """The scene and overrides of the sweeps and the robustness matrix."""
    return {"scene": config["studies_scene"], "overrides": config["studies_overrides"]}


def sweep_parts(name):
    """Jobs of a sweep: its `parts`, at most the length of the first dimension with >= 2 values."""
    spec = SWEEPS[name]
    lengths = [len(v) for v in spec["grid"].values() if len(v) >= 2]
    wanted = spec.get("parts", SWEEP_DEFAULTS["parts"])
    return max(1, min(wanted, lengths[0])) if lengths else 1


def sweep_settings(name):
    """A sweep's settings with the sweep_defaults filled in."""
    spec = SWEEPS[name]
    base = studies_scene()
    solver = {**SWEEP_DEFAULTS["solver"], **spec.get("solver", {})}
    return {
        "scene": base["scene"],
        "overrides": base["overrides"] + spec["overrides"] + [f"solver.{k}={v}" for k, v in solver.items()],
        "grid": spec["grid"],
        "time_budget": spec.get("time_budget", SWEEP_DEFAULTS["time_budget"]),
        "check_tol": spec.get("check_tol", SWEEP_DEFAULTS["check_tol"]),
        "parts": sweep_parts(name),
    }


def stability_settings():
    return {**studies_scene(), **STABILITY}


def tradeoff_settings():
    return {
        "scene": config["scene"],
        "overrides": config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()],
        "reference": {"mesh": REF["mesh"], "n": REF["n"], "stabilization": TRADEOFF["reference_stabilization"]},
        **{k: v for k, v in TRADEOFF.items() if k != "families"},
    }


def _check_sweeps():
    for name, spec in SWEEPS.items():
        dims = [dimension_name(k) for k in spec["grid"]]
        meshed = any(k.startswith("discretization.mesh") for k in spec["grid"])
        for kind, figure in spec["figures"].items():
            used = [figure[a] for a in ("x", "y", "hue", "across") if a in figure] + list(figure.get("select", {}))
            for dim in used:
                if dim not in dims:
                    raise config_error(STUDIES_SOURCE, f"sweeps.{name}.figures.{kind}",
                                       f"{dim!r} is not a dimension of the grid ({', '.join(dims)})")
            if kind == "profiles" and meshed:
                raise config_error(STUDIES_SOURCE, f"sweeps.{name}.figures.profiles", "the grid changes the mesh, "
                                   "so the contact nodes differ between points; drop the profiles figure")


def _check_tradeoff():
    for i, gain in enumerate(TRADEOFF["refinement_gain"]):
        for key in ("uniform", "refined"):
            if gain[key] not in TRADEOFF["families"]:
                raise config_error(STUDIES_SOURCE, f"tradeoff.refinement_gain[{i}].{key}", f"{gain[key]!r} is not "
                                   f"a family of tradeoff.families ({', '.join(TRADEOFF['families'])})")
    too_fine = [n for n in TRADEOFF["levels"] if n > REF["n"]]
    if too_fine:
        raise config_error(STUDIES_SOURCE, "tradeoff.levels", f"{too_fine[0]} > reference n = {REF['n']} "
                           "(config/config.yaml): errors are measured against the finer reference")


_check_sweeps()
_check_tradeoff()

SWEEP_TARGETS = [f"results/sweeps/{name}.nc" for name in SWEEPS] + [
    f"results/sweeps/{name}/{kind}.png" for name, spec in SWEEPS.items() for kind in spec["figures"]]
STABILITY_TARGETS = [f"results/stability/stability.{ext}" for ext in ("nc", "md", "png")]
#: the adaptive loop as a configuration of the speed-accuracy study (adaptivity.smk: rule tradeoff_adaptive)
TRADEOFF_ADAPTIVE = ["results/tradeoff/runs/adaptive.json"] if config["adaptivity_study"].get("tradeoff") else []
TRADEOFF_TARGETS = ["results/tradeoff/tradeoff.nc", "results/tradeoff/pareto.md", "results/tradeoff/pareto.png"]
EXTRAS_TARGETS = SWEEP_TARGETS + TRADEOFF_TARGETS + STABILITY_TARGETS


wildcard_constraints:
    label="[A-Za-z0-9][A-Za-z0-9_-]*",
    stab="|".join(["dofi", "dofi-2mu", "trace"]),
    n=r"[0-9]+(\.[0-9]+)?",
    fig="|".join(FIELD_FIGURES) if FIELD_FIGURES else "nofieldfigure",
