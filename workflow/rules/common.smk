# Configuration checks, file names and the targets; no rules here.
import json

from snakemake.exceptions import WorkflowError
from snakemake.utils import validate



def _validate_config():
    """Snakemake's validate (fills the defaults), its error cut to one line naming the key."""
    import jsonschema

    try:
        validate(config, "../schemas/config.schema.yaml")
    except WorkflowError as error:
        cause = error.__cause__ or error.__context__
        if not isinstance(cause, jsonschema.ValidationError):
            raise
        key = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in cause.absolute_path).lstrip(".")
        raise WorkflowError(f"invalid workflow configuration: {key or 'top level'}: {cause.message}; fix "
                            "config/config.yaml (schema: workflow/schemas/config.schema.yaml)") from None


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
                            "of 2 (nested with the square levels, SPEC 5)")


_check_config()


def ntag(n):
    """The n of a file name: 16, or 22.627417 for a non-integer n."""
    n = float(n)
    return str(int(n)) if n.is_integer() else repr(n)


def stabilization_free(label):
    """All-triangle families: the VEM space is P1 and the stabilization vanishes (SPEC 3)."""
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


wildcard_constraints:
    label="[A-Za-z0-9][A-Za-z0-9_-]*",
    stab="|".join(["dofi", "dofi-2mu", "trace"]),
    n=r"[0-9]+(\.[0-9]+)?",
    fig="|".join(FIELD_FIGURES) if FIELD_FIGURES else "nofieldfigure",
