"""BeamDyn input files as matrix sections, read with ``openfast-io`` (an optional dependency).

``section = { type = "beamdyn", file = "blade.dat" }``: ``file`` is a BeamDyn blade file (the
stations η = s/L and their 6×6 stiffness and mass matrices, BeamDyn's order and axes) or a
BeamDyn primary file (its ``BldFile`` is then read); the matrices become a
:class:`~beamfx.physics.matrix_sections.MatrixSection` in beamfx's order
(:func:`~beamfx.physics.matrix_sections.from_beamdyn`). The primary file's key points and
initial twist are :func:`read_primary`'s, for a scene's curve and ``twist_deg``.
"""

from pathlib import Path

import numpy as np


def _reader():
    try:
        from openfast_io.FAST_reader import InputReader_OpenFAST
    except ImportError as e:
        raise ValueError(
            "reading BeamDyn files needs the package openfast-io (pip install -c "
            "constraints.txt openfast-io; see scripts/install.sh)"
        ) from e
    return InputReader_OpenFAST()


def _is_primary(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return "BEAMDYN with OpenFAST INPUT FILE" in f.readline()


def read_primary(path):
    """The key points (n, 3) and initial twist (degrees, n) of the first member of a BeamDyn
    primary file, and the path of its blade file. Raises ValueError naming the file."""
    r = _reader()
    try:
        r.read_BeamDyn(str(path), 0)
        bd = r.fst_vt["BeamDyn"][0]
        member = bd["members"][0]
    except Exception as e:  # openfast-io raises whatever its parsing meets
        raise ValueError(
            f"{path}: openfast-io cannot read it as a BeamDyn primary file ({e})"
        ) from e
    points = np.column_stack([member[k] for k in ("kp_xr", "kp_yr", "kp_zr")]).astype(float)
    return points, np.asarray(member["initial_twist"], float), Path(path).parent / bd["BldFile"]


def read_blade(path):
    """(stations η, stiffness (n, 6, 6), mass (n, 6, 6)) of a BeamDyn blade file, or of the
    blade file a primary file names; BeamDyn's order. Raises ValueError naming the file."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    if _is_primary(path):
        path = read_primary(path)[2]
    r = _reader()
    try:
        r.read_BeamDynBlade(str(path), 0)
        blade = r.fst_vt["BeamDynBlade"][0]
        out = tuple(
            np.asarray(blade[k], float) for k in ("radial_stations", "beam_stiff", "beam_inertia")
        )
    except Exception as e:  # openfast-io raises whatever its parsing meets
        raise ValueError(f"{path}: openfast-io cannot read it as a BeamDyn blade file ({e})") from e
    if not all(np.all(np.isfinite(x)) for x in out):
        raise ValueError(f"{path}: a value is not finite")
    return out
