#!/usr/bin/env bash
# GetFEM for the peer comparison (benchmarks/peers.py, tests/benchmarks/test_peers.py): the Debian
# package python3-getfem for the system /usr/bin/python3. Installed only when missing, as root, with
# apt-get (no upgrade, no recommends; the package lists are refreshed only if the first try fails).
# Otherwise one line says why GetFEM is skipped. Never fails: without GetFEM its cases are skipped.
if /usr/bin/python3 -c "import getfem" >/dev/null 2>&1; then
    echo "GetFEM: python3-getfem found for /usr/bin/python3"
elif [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "GetFEM: skipped (python3-getfem is not installed; as root on Debian: apt-get install python3-getfem)"
else
    install=(apt-get install -y -qq --no-install-recommends python3-getfem)
    if DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1 ||
       { apt-get update -qq >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1; }; then
        echo "GetFEM: python3-getfem installed for /usr/bin/python3"
    else
        echo "GetFEM: skipped (apt-get install python3-getfem failed)"
    fi
fi
exit 0
