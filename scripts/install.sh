#!/usr/bin/env bash
# Idempotent installer for beamfx on Debian 12 (bookworm):
#   1. apt packages (DOLFINx 0.5.2 stack), only if some are missing
#   2. .venv with --system-site-packages on /usr/bin/python3
#   3. pip tools + editable beamfx, skipped when the stamp file matches
#   4. bytecode of beamfx (best effort)
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT=$PWD
VENV=$ROOT/.venv
PY=/usr/bin/python3

APT_PKGS=(
  python3-dolfinx python3-petsc4py python3-slepc4py python3-gmsh python3-meshio
  python3-mpi4py openmpi-bin python3-venv python3-dev build-essential git make
  paraview python3-paraview xvfb xauth  # pvpython; Debian's ParaView renders through X only
)
# openfast-io reads BeamDyn files (section type "beamdyn"); 4.2.1 is the last that reads the
# BeamDyn v1.00 blade files of meshes/nrel5mw (5.0.0 expects a modal-damping block)
PIP_PKGS=("pytest>=8" pytest-xdist pytest-timeout pyvista matplotlib imageio ruff openfast-io sectionproperties)

log() { printf '[install] %s\n' "$*"; }

# --- 1. apt ---------------------------------------------------------------
missing=()
for p in "${APT_PKGS[@]}"; do
  if [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" != "install ok installed" ]]; then
    missing+=("$p")
  fi
done
if ((${#missing[@]})); then
  log "apt: installing missing packages: ${missing[*]}"
  SUDO=()
  if [[ $(id -u) -ne 0 ]]; then
    if command -v sudo >/dev/null 2>&1; then
      SUDO=(sudo)
    else
      log "ERROR: need root or sudo to install: ${missing[*]}" >&2
      exit 1
    fi
  fi
  "${SUDO[@]}" apt-get update
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y --no-install-recommends "${APT_PKGS[@]}"
else
  log "apt: all ${#APT_PKGS[@]} packages present"
fi

# --- 2. venv --------------------------------------------------------------
if [[ ! -x $VENV/bin/python ]]; then
  log "venv: creating $VENV (system site packages, $PY)"
  "$PY" -m venv --system-site-packages "$VENV"
else
  log "venv: $VENV exists"
fi

# --- 3. pip ---------------------------------------------------------------
hash=$(cat pyproject.toml constraints.txt scripts/install.sh | sha256sum | cut -c1-16)
stamp=$VENV/.installed-$hash
if [[ -e $stamp ]]; then
  log "pip: up to date (${stamp#"$ROOT"/})"
else
  export PIP_CONSTRAINT=$ROOT/constraints.txt
  export PIP_DISABLE_PIP_VERSION_CHECK=1
  log "pip: installing ${PIP_PKGS[*]} (constraints.txt)"
  "$VENV/bin/python" -m pip install --quiet "${PIP_PKGS[@]}"
  log "pip: installing beamfx (editable)"
  "$VENV/bin/python" -m pip install --quiet -e .
  want=$(grep -E '^numpy==' constraints.txt | cut -d= -f3)
  have=$("$VENV/bin/python" -c 'import numpy; print(numpy.__version__)')
  if [[ $have != "$want" ]]; then
    log "ERROR: venv numpy is $have, expected $want (Debian's)" >&2
    exit 1
  fi
  rm -f "$VENV"/.installed-*
  touch "$stamp"
  log "pip: done (numpy $have)"
fi
# --- 4. bytecode -----------------------------------------------------------
# beamfx's modules compiled once (only what changed since): a process never writes them where
# PYTHONDONTWRITEBYTECODE is set (or the checkout is read-only), and then compiles all of
# them at every start (0.1 s of a `beamfx run`); best effort: a module not written is not an
# install's failure
if ! "$VENV/bin/python" -m compileall -q beamfx >/dev/null; then
  log "bytecode: not every module written (read-only checkout?): runs compile them at start"
fi
log "ready: $VENV/bin/beamfx"
