#!/usr/bin/env bash
# Peer codes for `make bench-peers`, in their own venv: no system site packages,
# so their numpy (and its BLAS) is independent of the one DOLFINx uses.
# Idempotent: a second run with everything in place takes about a second.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${PEERS_VENV:-.venv-peers}
PKGS=(exudyn pyelastica numpy matplotlib)

if [ ! -x "$VENV/bin/python" ]; then
  /usr/bin/python3 -m venv "$VENV"
fi
if "$VENV/bin/python" -c "import exudyn, elastica, numpy, matplotlib" 2>/dev/null; then
  exit 0
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "${PKGS[@]}"
"$VENV/bin/python" - <<'PY'
import exudyn, elastica, numpy
print("peers: exudyn", exudyn.__version__, "| pyelastica", getattr(elastica, "__version__", "?"),
      "| numpy", numpy.__version__)
PY
