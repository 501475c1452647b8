"""``beamfx run`` of one bench setting in a process of its own, timed from outside: the time a
user waits for the command (interpreter start, imports, model, solve, output).

    python -m beamfx.bench.process <case id> <output folder> <elements> <degree> [<dt> [<scheme>]]

The scene is built in code by the case (:func:`beamfx.bench.scenes.setting_scene`) and then run
by :func:`beamfx.runner.run_scene`, the call behind ``beamfx run``.
"""

import subprocess
import sys
import time


def process_seconds(case_id, setting, folder):
    """Wall time of the child process that runs the ``setting`` ((elements, degree) or, for
    a transient, (elements, degree, dt) or (elements, degree, dt, scheme)) of a case (warm JIT
    cache)."""
    cmd = [sys.executable, "-m", __name__, case_id, str(folder), *(str(x) for x in setting)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - t0


def main(argv):
    """Child process: run one setting of a case through :func:`~beamfx.runner.run_scene`."""
    case_id, folder, elements, degree, *dt = argv  # dt and the scheme of a transient
    from ..runner import run_scene
    from . import all_cases
    from .scenes import setting_scene

    case = all_cases()[case_id]
    setting = (int(elements), int(degree), *(float(x) for x in dt[:1]), *dt[1:])
    if hasattr(case, "scenes"):  # a case of several scenes (eigen analyses)
        scenes = case.scenes(*setting)
    else:
        scenes = [setting_scene(case, setting)]
    for scene in scenes:
        run_scene(scene.file, folder, log=lambda *a, **k: None, scene=scene)


if __name__ == "__main__":
    main(sys.argv[1:])
