"""A traction or pressure with a pole between two vertices of its side is refused before any solve,
in one line naming the key, the side and the point (issue 33, item 5: such a load was integrated by
the edge rule as if it existed), while integrable and bounded loads still solve; through the real
command."""

import subprocess
import sys

import pytest

SCENE = """name: pole
material: {E: 100, nu: 0.3}
domain: {polygon: [[0, 0], [3, 0], [3, 2], [0, 2]], sides: [bottom, load, top, clamped]}
boundary: {dirichlet: {clamped: [0, 0]}, neumann: {bottom: LOAD}}
discretization: {mesh: {family: square, n: 2}}
"""
KEY = {"pressure": "boundary.neumann.bottom.pressure", "traction": "boundary.neumann.bottom.traction[1]"}


def vemkit(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300
    )


def _solve(tmp_path, kind: str, text: str):
    load = f'{{pressure: "{text}"}}' if kind == "pressure" else f'{{traction: [0, "{text}"]}}'
    (tmp_path / "s.yaml").write_text(SCENE.replace("LOAD", load))
    return vemkit("solve", "s.yaml", "-o", "out.nc", "-q", cwd=tmp_path)


@pytest.mark.parametrize(
    "kind, text, growth",
    [
        ("pressure", "1/(x-0.37)", "1/d^1 "),
        ("pressure", "1/abs(x-0.37)**1.5", "1/d^1.5 "),
        ("traction", "where(x > 0.37, 1/(x-0.37), 0)", "1/d^1 "),
    ],
)
def test_a_pole_between_vertices_is_refused(tmp_path, kind, text, growth):
    run = _solve(tmp_path, kind, text)
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
    assert f"{KEY[kind]} = '{text}': not integrable on side 'bottom': it grows like {growth}" in run.stderr
    assert "from (0.37, 0)" in run.stderr and "move the pole off it" in run.stderr, run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


@pytest.mark.parametrize("text", ["1/sqrt(abs(x-0.37))", "log(abs(x-0.37))", "1/(x-3.0000001)", "where(x > 0.5, 1, 0)"])
def test_an_integrable_load_still_solves(tmp_path, text):
    run = _solve(tmp_path, "pressure", text)
    assert run.returncode == 0, run.stderr


def test_a_singular_plane_across_3d_faces_is_refused(tmp_path):
    """3D: the pole plane x = 0.37 crosses the edges of the loaded faces: refused there; 1/sqrt solves."""
    scene = (
        "name: p3\nmodel: 3d\ndomain: {box: [[0, 0, 0], [1, 1, 0.5]]}\nmaterial: {E: 1000, nu: 0.3}\n"
        'boundary:\n  dirichlet: {bottom: [0, 0, 0]}\n  neumann: {top: {pressure: "P"}}\n'
        "discretization: {mesh: {family: octree, n: 2}}\n"
    )
    for text, status in (("1/(x-0.37)", 2), ("1/sqrt(abs(x-0.37))", 0)):
        (tmp_path / "s.yaml").write_text(scene.replace("P", text))
        run = vemkit("solve", "s.yaml", "-o", "out.nc", "-q", cwd=tmp_path)
        assert run.returncode == status, run.stderr
    (tmp_path / "s.yaml").write_text(scene.replace("P", "1/(x-0.37)"))
    run = vemkit("solve", "s.yaml", "-o", "again.nc", cwd=tmp_path)
    assert len(run.stderr.splitlines()) == 1 and "'1/(x-0.37)': not integrable on side 'top'" in run.stderr
    assert "from (0.37, " in run.stderr and not (tmp_path / "again.nc").exists()
