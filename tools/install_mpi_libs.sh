#!/usr/bin/env bash
# System packages of the `mpi` extra (mpi4py, petsc, petsc4py; solver.linear: petsc). pip builds
# petsc and mpi4py from source, so they need a C compiler, an MPI (Debian's MPICH: mpicc, mpiexec,
# libmpich) and BLAS/LAPACK (Debian's OpenBLAS and LAPACK). petsc is configured without Fortran
# (PETSC_CONFIGURE_OPTIONS in the Makefile), so no gfortran. When they are all there this prints one
# line and changes nothing; otherwise, as root on Debian, it installs the missing packages (no
# recommends; the package lists are refreshed only if the first try fails). Never fails: without
# them `pip install .[mpi]` fails and says which library it lacks.
PKGS=(gcc make pkg-config libmpich-dev mpich libopenblas-dev liblapack-dev)
have_all() {
    command -v mpicc >/dev/null 2>&1 && command -v mpiexec >/dev/null 2>&1 &&
        command -v gcc >/dev/null 2>&1 && command -v make >/dev/null 2>&1 &&
        { ldconfig -p | grep -q 'liblapack\.so ' || [ -e /usr/lib/x86_64-linux-gnu/liblapack.so ]; }
}
if have_all; then
    echo "mpi: mpicc, mpiexec, gcc and LAPACK found ($(mpichversion 2>/dev/null | head -1 | tr -s ' \t' ' ' || mpicc -show | cut -d' ' -f1))"
elif [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "mpi: a C compiler, MPI or LAPACK is missing; as root on Debian: apt-get install ${PKGS[*]}"
else
    install=(apt-get install -y -qq --no-install-recommends "${PKGS[@]}")
    if DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1 ||
       { apt-get update -qq >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1; }; then
        echo "mpi: installed ${PKGS[*]}"
    else
        echo "mpi: apt-get install ${PKGS[*]} failed; the mpi extra will not build"
    fi
fi
exit 0
