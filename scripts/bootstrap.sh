#!/usr/bin/env bash
# Idempotent set-up of the housingfe environment on Debian bookworm:
#   1. Debian packages (FEniCSx 0.5.2, PETSc/SLEPc 3.18, gmsh, CalculiX, OpenBLAS, Mesa EGL) via apt,
#   2. a virtual environment .venv made from the system interpreter with --system-site-packages,
#   3. housingfe installed editable with its PyPI extras, numpy pinned to Debian's 1.24.2.
# Fast (< 2 s) when everything is already in place. Used by `make`, .ci/run and docker/Dockerfile.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${HOUSINGFE_VENV:-$here/.venv}"
extras="${HOUSINGFE_EXTRAS:-test}"

debian_packages=(
  python3-dolfinx-real python3-dolfinx-complex python3-petsc4py python3-slepc4py
  python3-gmsh python3-meshio python3-venv python3-dev
  python3-cffi                  # housingfe.solvers.mumps calls MUMPS directly (also a dependency of FFCx)
  libopenblas0-pthread          # MUMPS is ~2x slower on the reference BLAS (STACK-NOTES)
  openmpi-bin                   # mpirun for multi-rank runs
  calculix-ccx                  # peer solver for `housingfe bench modal`
  libegl1 libegl-mesa0 libgl1-mesa-dri   # off-screen pyvista pictures without X
  gcc g++ make                  # FFCx JIT-compiles forms at first use
)

missing=()
for p in "${debian_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing Debian packages: ${missing[*]}" >&2
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

if [ ! -x "$venv/bin/python" ]; then
  echo "bootstrap: creating $venv" >&2
  /usr/bin/python3 -m venv --system-site-packages "$venv"
fi

# Reinstall only when the project's metadata changed since the last successful install.
stamp="$venv/.housingfe-installed"
# Offline install (container builds, air-gapped machines, proxies that break TLS): when a wheelhouse exists
# (docker/build.sh fills ./wheelhouse), PyPI packages come only from it. Without one, from the index as before.
wheelhouse="${HOUSINGFE_WHEELHOUSE:-$here/wheelhouse}"
pip_source=()
[ ! -d "$wheelhouse" ] || pip_source=(--no-index --find-links "$wheelhouse")
if [ ! -f "$stamp" ] || [ "$here/pyproject.toml" -nt "$stamp" ] || [ "$here/scripts/constraints.txt" -nt "$stamp" ]; then
  echo "bootstrap: installing housingfe[$extras] into $venv${pip_source:+ from $wheelhouse}" >&2
  "$venv/bin/python" -m pip install -q --disable-pip-version-check "${pip_source[@]}" \
      -c "$here/scripts/constraints.txt" -e "$here[$extras]" >&2 \
    || { [ ${#pip_source[@]} -eq 0 ] || echo "bootstrap: $wheelhouse lacks a package: refresh it" \
           "(bash docker/build.sh does) or remove it to install from PyPI" >&2; exit 1; }
  touch "$stamp"
fi
