"""vemkit: lowest-order virtual elements for elastic bodies in frictional contact.

The public API (each name is imported on first use, so ``import vemkit`` is cheap and has no side
effects)::

    scene = vemkit.load_scene("config/scenes/paper.yaml", ["discretization.mesh.n=32"])
    mesh = vemkit.build_mesh("voronoi", 32, seed=1)              # or vemkit.scene_mesh(scene)
    space = vemkit.VirtualElementSpace(mesh, 2)                  # one space, any element (k = 1, 2)
    problem = vemkit.discrete_problem(mesh, E=2000.0, nu=0.4, dirichlet=["right"], contact=["bottom"], order=2)
    problem = vemkit.scene_problem(scene)                       # the same from a scene
    solution = vemkit.solve(problem, scene.solver_options)      # ssn or uzawa
    ds = vemkit.solution_dataset(problem, solution)             # xarray.Dataset (docs/reference/files.md)
    mesh, ds = vemkit.read_solution("paper.nc")

Layers (each subpackage imports only the ones before it): ``exceptions`` → ``config`` → ``mesh``
→ ``vem`` → ``contact`` → ``solvers`` → ``io`` → ``studies`` → ``report`` → ``cli``.
"""

from importlib import import_module

__version__ = "0.1.0"

_API = {
    "Mesh": "vemkit.mesh.mesh",
    "build_mesh": "vemkit.mesh.families",
    "scene_mesh": "vemkit.mesh.meshing",
    "validate_mesh": "vemkit.mesh.checks",
    "load_scene": "vemkit.config.scene",
    "VirtualElementSpace": "vemkit.vem.space",
    "element_for": "vemkit.vem.elements",
    "discrete_problem": "vemkit.contact.problem",
    "scene_problem": "vemkit.contact.problem",
    "solve": "vemkit.solvers.dispatch",
    "solution_dataset": "vemkit.studies.scene_solve",
    "read_solution": "vemkit.io.solution_file",
}
__all__ = sorted(_API) + ["__version__"]


def __getattr__(name):
    if name in _API:
        value = getattr(import_module(_API[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'vemkit' has no attribute {name!r}")


def __dir__():
    return __all__
