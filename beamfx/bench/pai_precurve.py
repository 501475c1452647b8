"""Which way is the rotating Pai beam pre-curved? Both, side by side (Howcroft et al. 2016, §4.3).

The source gives the pre-curvature's magnitude and a sign in its own axes and shows the
direction only in a figure; ``beamfx/scenes/pai_rotating.toml`` curves the strip down, towards
gravity. This module runs the same scene with the arc curved up (the arc's centre mirrored
above the clamp) and prints, for both, the settled tip at each speed of the scene and where the
first rotating-frame frequency crosses the 4.5 Hz excitation (the sweep of
:mod:`beamfx.bench.pai_spin_ramp`). ``python -m beamfx.bench.pai_precurve`` (about a minute).
"""

import math
import tempfile

from .pai_spin_ramp import EXCITATION_HZ, crossing, lowest, scene_data, sweep_hz


def scene(up, elements=8, degree=3, speeds_hz=None, modes=2):
    """The rotating scene curved down (``up`` False: the packaged one) or up."""
    from ..scene.load import parse_scene

    data = scene_data("pai_rotating.toml")
    beam = data["beams"][0]
    beam.update(elements=elements, degree=degree)
    if up:
        beam["curve"]["centre"] = [
            c * (-1 if i == 2 else 1) for i, c in enumerate(beam["curve"]["centre"])
        ]
    if speeds_hz is not None:
        data["analysis"]["speeds_rad_s"] = [2 * math.pi * f for f in speeds_hz]
    data["analysis"]["modes"] = modes
    return parse_scene(data, "pai_rotating.toml")


def run(up):
    """(tips per scene speed {Hz: (y, z)}, f1 crossing in Hz) of one direction."""
    from .scenes import run_in_process

    with tempfile.TemporaryDirectory() as folder:
        settled = run_in_process(scene(up), folder)[0].result
        tips = {
            round(s["speed_rad_s"] / (2 * math.pi)): tuple(s["probes"]["tip"]["position"][1:])
            for s in settled.path
        }
        result = run_in_process(scene(up, speeds_hz=sweep_hz()), folder)[0].result
    spin, _ = crossing(*lowest(result))
    return tips, spin


def main():
    """Print the table (markdown)."""
    rows = {name: run(up) for name, up in (("down (the scene)", False), ("up", True))}
    speeds = sorted(next(iter(rows.values()))[0])
    print(
        "| pre-curved | "
        + " | ".join(f"tip y, z at {f} Hz (m)" for f in speeds)
        + " | f1 = 4.5 Hz at |"
    )
    print("|---" * (len(speeds) + 2) + "|")
    for name, (tips, spin) in rows.items():
        cells = " | ".join(f"{tips[f][0]:.4f}, {tips[f][1]:.4f}" for f in speeds)
        print(f"| {name} | {cells} | {spin:.4f} Hz |")
    print(f"(8 x P3; f1 against the {EXCITATION_HZ} Hz line by linear interpolation in the sweep)")


if __name__ == "__main__":
    main()
