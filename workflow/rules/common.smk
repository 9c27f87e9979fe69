# Configuration checks, file names and the targets; no rules here. Every other rule file uses only
# what this file defines (the Snakefile includes it first).
#
# The configuration is Snakemake's own `config`: config/config.yaml (the paper) and
# config/sweeps.yaml (the studies), merged with any `--configfile` / `--config` of the command line.
# Each part is validated against its schema (a key that no schema knows is an error), then every check
# beyond the schemas (vemkit.studies.workflow_config): all before any job, also in `snakemake -n`; a
# refusal is one line naming the file that set the key, the key and the fix (exit 1, no traceback).
import sys
from pathlib import Path

import yaml

from vemkit.exceptions import WorkflowConfigError

#: part of the configuration: (schema, the file that sets its defaults)
CONFIG_PARTS = {
    "paper": ("../schemas/config.schema.yaml", "config/config.yaml"),
    "studies": ("../schemas/sweeps.schema.yaml", "config/sweeps.yaml"),
    "adaptivity": ("../schemas/adaptivity.schema.yaml", "config/adaptivity.yaml"),
    "adaptivity3d": ("../schemas/adaptivity3d.schema.yaml", "config/adaptivity3d.yaml"),
    "three_d": ("../schemas/three_d.schema.yaml", "config/three_d.yaml"),
}


def _config_layers():
    """[(name, data)] of what set the config, lowest priority first: the Snakefile's files, each
    --configfile, --config."""
    def shown(path):
        path = Path(path)
        try:
            return str(path.resolve().relative_to(Path.cwd().resolve()))
        except ValueError:
            return str(path)

    layers = []
    for name in [source for _, source in CONFIG_PARTS.values()] + [shown(p) for p in workflow.overwrite_configfiles]:
        try:
            layers.append((name, yaml.safe_load(Path(name).read_text(encoding="utf-8")) or {}))
        except (OSError, yaml.YAMLError):
            layers.append((name, {}))
    return layers + [("--config", dict(workflow.config_settings.config or {}))]


def config_failure(error: WorkflowConfigError):
    """One line naming the file that set the key, the key, the problem and the fix; exit 1, before any job."""
    from vemkit.studies.workflow_config import config_source

    print(f"{config_source(error.path, _config_layers())}: {error.key}: {error}", file=sys.stderr)
    raise SystemExit(1)


def _schema_path(error):
    """The config key of a jsonschema error (an unknown key: that key)."""
    path = list(error.absolute_path)
    if error.validator == "additionalProperties" and isinstance(error.instance, dict):
        known = error.schema.get("properties", {})
        path += [next((k for k in error.instance if k not in known), "?")]
    return path


def _validated(data, schema):
    """Snakemake's validate (fills the defaults in place), its error as a WorkflowConfigError."""
    import jsonschema
    from snakemake.exceptions import WorkflowError
    from snakemake.utils import validate

    try:
        validate(data, schema)
    except WorkflowError as error:
        cause = error.__cause__ or error.__context__
        if not isinstance(cause, jsonschema.ValidationError):
            raise
        from vemkit.config.scene_schema import suggest

        path = _schema_path(cause)
        if cause.validator == "additionalProperties" and isinstance(cause.instance, dict):
            problem = f"unknown key{suggest(path[-1], cause.schema.get('properties', {}))}"
        else:
            problem = f"{cause.message} (workflow/schemas/{Path(schema).name}); fix the value"
        raise WorkflowConfigError(problem, path=path) from None


def _validate_config():
    """Every part against its schema, then the checks beyond the schemas (vemkit.studies.workflow_config:
    cross-field constraints, every value forwarded into a scene through the scene's validation)."""
    from vemkit.studies.workflow_config import check_workflow_config

    schema_dir = Path(workflow.current_basedir)
    known = set()
    for schema, _ in CONFIG_PARTS.values():
        keys = set(yaml.safe_load((schema_dir / schema).read_text(encoding="utf-8"))["properties"])
        part = {k: v for k, v in config.items() if k in keys}
        _validated(part, schema)
        config.update(part)
        known |= keys
    unknown = sorted(set(config) - known)
    if unknown:
        raise WorkflowConfigError("unknown key (the workflow reads the keys of workflow/schemas/*.schema.yaml); "
                                  "drop it or fix its spelling", path=[unknown[0]])
    check_workflow_config(config)


try:
    _validate_config()
except WorkflowConfigError as error:
    config_failure(error)

MESHES = config["meshes"]
STABS = list(config["stabilizations"])
LEVELS = sorted(config["levels"])
BATCH = config["batch_levels"]
REF = config["reference"]
FIG = config["figures"]
FIG_STAB = FIG["stabilization"]


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
