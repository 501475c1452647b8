#!/usr/bin/env bash
# Peer codes for `make bench-peers`, in their own venv: no system site packages,
# so their numpy (and its BLAS) is independent of the one DOLFINx uses. CalculiX (`ccx`)
# comes from Debian (apt-get, with sudo unless root).
# Idempotent: a second run with everything in place takes about a second.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${PEERS_VENV:-.venv-peers}
PKGS=(exudyn pyelastica numpy matplotlib "openseespy==3.8.0.0")

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
if "$VENV/bin/python" -c "import exudyn, elastica, numpy, matplotlib, openseespy.opensees" 2>/dev/null; then
  exit 0
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "${PKGS[@]}"
"$VENV/bin/python" - <<'PY'
import exudyn, elastica, numpy, openseespy.opensees
print("peers: exudyn", exudyn.__version__, "| pyelastica", getattr(elastica, "__version__", "?"),
      "| openseespy", getattr(openseespy.opensees, "version", lambda: "?")(), "| numpy", numpy.__version__)
PY
