"""pyBModes (pypi `pybmodes`) on the NREL 5-MW blade: the first 6 frequencies at 0 and 12.1 rpm,
written to DIR/pybmodes_blade.json (a peer of beamfx's rotating-blade case, issue 18).

The blade is the one pyBModes ships: the BModes input
``_examples/sample_inputs/reference_turbines/01_nrel5mw_land/01_nrel5mw_land_blade.bmi`` (rotating
cantilever, 61.5 m flexible length from the 1.5 m hub radius to the 63 m tip radius, precone
-2.5°, 20 elements) and its section table ``01_nrel5mw_land_blade_sec_props.dat``: the 49
stations of Jonkman et al. (2009), Table 2-1 (structural twist, mass, flap and edge stiffness)
with pyBModes' stand-ins for what that table lacks (rotary inertias ~1e-5 of the mass, torsion
stiffness 100 x and axial stiffness 1e6 x the edge stiffness: rigid in practice). The
ElastoDyn form of the same table is ``_examples/reference_decks/nrel5mw_land/
NRELOffshrBsline5MW_Blade.dat``. Each speed is the shipped file with only ``rot_rpm`` changed.
Times: ``first_s`` the first model read and solve in the process, ``whole_s`` the second,
``meta.import_s`` a fresh interpreter importing pybmodes.

    .venv-peers/bin/python peers/pybmodes_blade.py DIR
"""

import json
import re
import shutil
import sys
import time
from importlib.metadata import version
from pathlib import Path

import common

SPEEDS_RPM = (0.0, 12.1)
N_FREQ = 6
SAMPLE = Path("_examples/sample_inputs/reference_turbines/01_nrel5mw_land")
BMI, SEC = "01_nrel5mw_land_blade.bmi", "01_nrel5mw_land_blade_sec_props.dat"


def blade_files(folder, rpm):
    """The shipped BMI with ``rot_rpm`` = ``rpm`` and its section table, copied to
    ``folder``; the BMI's path."""
    import pybmodes

    src = Path(pybmodes.__file__).parent / SAMPLE
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(src / SEC, folder / SEC)
    text, n = re.subn(
        r"(?m)^\s*[-+.0-9eE]+(\s+rot_rpm:)",
        lambda m: f"{rpm:g}{m.group(1)}",
        (src / BMI).read_text(),
    )
    if n != 1:
        raise ValueError(f"{BMI}: no single rot_rpm line")
    path = folder / f"blade_{rpm:g}rpm.bmi"
    path.write_text(text)
    return path


def frequencies(bmi):
    """The first :data:`N_FREQ` natural frequencies (Hz) of the blade of ``bmi``."""
    from pybmodes.models import RotatingBlade

    return [float(f) for f in RotatingBlade(bmi).run(n_modes=N_FREQ).frequencies[:N_FREQ]]


def main():
    out_dir = Path(common.out_dir())
    records = []
    for rpm in SPEEDS_RPM:
        bmi = blade_files(out_dir / "pybmodes_blade", rpm)
        t0 = time.perf_counter()
        frequencies(bmi)
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        f = frequencies(bmi)
        whole = time.perf_counter() - t0
        records.append({"rpm": rpm, "frequencies_hz": f, "first_s": first, "whole_s": whole})
        print(f"pyBModes NREL 5-MW blade, {rpm:g} rpm: " + ", ".join(f"{x:.4f}" for x in f) + " Hz")
    meta = {
        "pybmodes": version("pybmodes"),
        "import_s": common.import_seconds("numpy", "pybmodes.models"),
        "bmi": str(SAMPLE / BMI),
        "sec_props": str(SAMPLE / SEC),
    }
    path = out_dir / "pybmodes_blade.json"
    path.write_text(json.dumps({"meta": meta, "records": records}, indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
