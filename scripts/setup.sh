#!/usr/bin/env bash
# Create .venv/ at the repository root and install grasp_torque_opt into it
# (editable), with ROS 2 Jazzy from the registry's ros-jazzy-* wheels, Pinocchio,
# ProxSuite, the test tools, the benchmarks' extra solvers, MuJoCo (the
# simulated hand) and Dask distributed (batch scoring on a cluster), building the
# compiled cycle (g++ and Python's headers, installed with apt where missing and
# possible). Idempotent: a second run only checks.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON="${PYTHON:-python3}"
if ! "$PYTHON" -c 'import sys; assert (3, 10) <= sys.version_info[:2] <= (3, 13)' 2>/dev/null; then
    echo "setup: need Python 3.10 to 3.13 as '$PYTHON' (set PYTHON=...)" >&2
    exit 1
fi
if [ ! -x .venv/bin/python ]; then
    if ! "$PYTHON" -m venv .venv 2>/dev/null; then
        # Debian and Ubuntu ship venv separately.
        rm -rf .venv
        if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
            apt-get update -qq
            ver="$("$PYTHON" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')"
            apt-get install -y -qq "python${ver}-venv" || apt-get install -y -qq python3-venv
            "$PYTHON" -m venv .venv
        else
            echo "setup: '$PYTHON -m venv' failed; install python3-venv" >&2
            exit 1
        fi
    fi
fi
# The compiled cycle (src/, docs/design.md section 2.6) needs a C++ compiler and
# Python's headers; without them the package installs and the node runs its Python
# cycle, 3 to 4 times slower (and test_the_compiled_cycle_is_built says so).
include="$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
if ! command -v c++ >/dev/null || [ ! -f "$include/Python.h" ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        apt-get update -qq
        ver="$("$PYTHON" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')"
        apt-get install -y -qq g++ "python${ver}-dev" || apt-get install -y -qq g++ python3-dev
    else
        echo "setup: no C++ compiler or no Python.h: the compiled cycle will not be built" \
             "(install g++ and python3-dev for it)" >&2
    fi
fi
stamp=.venv/.installed
# Again when the build inputs change: setup.py, pyproject.toml, or the compiled cycle's
# source (an editable install does not rebuild it by itself).
if [ ! -f "$stamp" ] || [ setup.py -nt "$stamp" ] || [ pyproject.toml -nt "$stamp" ] ||
        [ -n "$(find src -newer "$stamp" -print -quit)" ]; then
    .venv/bin/python -m pip install -q --upgrade pip
    .venv/bin/python -m pip install -q -e '.[ros,test,bench,sim,distributed]'
    touch "$stamp"
fi
