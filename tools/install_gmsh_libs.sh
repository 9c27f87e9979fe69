#!/usr/bin/env bash
# System libraries of the gmsh wheel (mesh family tet, kind delaunay: vemkit/mesh/families3d/gmsh_tet.py).
# The PyPI wheel's libgmsh.so links OpenGL and X11 client libraries (its GUI is built in) even when
# used headless: libGLU, libGL, libXcursor, libXft, libXinerama, libXrender, libXext, libX11,
# fontconfig and libgomp. The Debian image of this project ships them all, so here this prints one
# line and does nothing; on a slimmer Debian, as root, it installs the packages that hold them (no
# recommends; the package lists are refreshed only if the first try fails). Never fails: without
# them only the delaunay tet family is unavailable, with a one-line MeshError saying so.
PY="${1:-python3}"
PKGS=(libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libxrender1 libxext6 libx11-6 libfontconfig1 libgomp1)
if "$PY" -c "import gmsh" >/dev/null 2>&1; then
    echo "gmsh: the Python package imports ($("$PY" -c 'import gmsh; print(gmsh.__version__)' 2>/dev/null))"
elif ! "$PY" -c "import importlib.util, sys; sys.exit(importlib.util.find_spec('gmsh') is None)" >/dev/null 2>&1; then
    echo "gmsh: the Python package is not installed (pip install gmsh); mesh family tet kind delaunay unavailable"
elif [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "gmsh: installed but cannot load its libraries; as root on Debian: apt-get install ${PKGS[*]}"
else
    install=(apt-get install -y -qq --no-install-recommends "${PKGS[@]}")
    if DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1 ||
       { apt-get update -qq >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1; }; then
        if "$PY" -c "import gmsh" >/dev/null 2>&1; then
            echo "gmsh: installed its system libraries (${PKGS[*]})"
        else
            echo "gmsh: still cannot be imported after installing ${PKGS[*]}: $("$PY" -c 'import gmsh' 2>&1 | tail -1)"
        fi
    else
        echo "gmsh: apt-get install ${PKGS[*]} failed; mesh family tet kind delaunay unavailable"
    fi
fi
exit 0
