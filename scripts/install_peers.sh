#!/usr/bin/env bash
# Peer codes for `make bench-peers`, in their own venv: no system site packages,
# so their numpy (and its BLAS) is independent of the one DOLFINx uses. CalculiX (`ccx`)
# comes from Debian (apt-get, with sudo unless root).
# Idempotent: a second run with everything in place takes about a second.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${PEERS_VENV:-.venv-peers}
# openseespy 3.8 needs Python >= 3.12 (its openseespylinux wheel); 3.7.1.2 is the newest for Debian 12's 3.11
# Pinned as resolved on 2026-11-23 (Debian 12, Python 3.11)
PKGS=("exudyn==1.13.6" "pyelastica==1.0.0" "numpy==2.4.6" "matplotlib==3.11.2"
  "openseespy==3.7.1.2" "pybmodes==1.19.1")

# CalculiX (Debian `calculix-ccx`, binary `ccx`): checked before the fast path below
if ! command -v ccx >/dev/null 2>&1; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends calculix-ccx \
    || { $SUDO apt-get update -q && $SUDO env DEBIAN_FRONTEND=noninteractive \
      apt-get install -y --no-install-recommends calculix-ccx; }
  echo "peers: ccx $(dpkg-query -W -f='${Version}' calculix-ccx 2>/dev/null || echo '?')"
fi

if [ ! -x "$VENV/bin/python" ]; then
  /usr/bin/python3 -m venv "$VENV"
fi
if "$VENV/bin/python" -c "import exudyn, elastica, numpy, matplotlib, openseespy.opensees, pybmodes" 2>/dev/null; then
  exit 0
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "${PKGS[@]}"
"$VENV/bin/python" - <<'PY'
from importlib.metadata import version
import openseespy.opensees
print("peers:", " | ".join(f"{p} {version(p)}" for p in
      ("exudyn", "pyelastica", "openseespy", "pybmodes", "numpy")))
PY
