"""``beamfx run`` of one bench setting in a process of its own, timed from outside: the time a
user waits for the command (interpreter start, imports, model, solve, output).

    python -m beamfx.bench.process <module> <case id> <output folder> <elements> <degree> [<dt> [<scheme>]]

(``module``: the one that registers the case, imported alone.)

The scene is built in code by the case (:func:`beamfx.bench.scenes.setting_scene`) and then run
by :func:`beamfx.runner.run_scene`, the call behind ``beamfx run``.
"""

import subprocess
import sys
import time


def process_seconds(case_id, setting, folder):
    """Wall time of the child process that runs the ``setting`` ((elements, degree) or, for
    a transient, (elements, degree, dt) or (elements, degree, dt, scheme)) of a case (warm JIT
    cache): the second of two runs, so that the disk cache is warm, as the peers' processes
    are timed (``peers/common.py``, ``import_seconds``)."""
    from .registry import REGISTERED_IN

    args = (REGISTERED_IN[case_id], case_id, str(folder), *(str(x) for x in setting))
    cmd = [sys.executable, "-m", __name__, *args]
    for _ in range(2):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        seconds = time.perf_counter() - t0
    return seconds


def main(argv):
    """Child process: run one setting of a case through :func:`~beamfx.runner.run_scene`, after
    what the ``beamfx`` command does first (:func:`beamfx.startup.prepare`, ``gc.freeze``)."""
    import gc

    from ..startup import prepare

    prepare()
    module, case_id, folder, elements, degree, *dt = argv  # dt and the scheme of a transient
    from importlib import import_module

    from ..runner import run_scene
    from .registry import REGISTRY
    from .scenes import setting_scene

    import_module(module)  # the case's own module (not every paper's: some compute at import)
    case = REGISTRY[case_id]
    setting = (int(elements), int(degree), *(float(x) for x in dt[:1]), *dt[1:])
    if hasattr(case, "scenes"):  # a case of several scenes (eigen analyses)
        scenes = case.scenes(*setting)
    else:
        scenes = [setting_scene(case, setting)]
    gc.freeze()
    for scene in scenes:
        run_scene(scene.file, folder, log=lambda *a, **k: None, scene=scene)


if __name__ == "__main__":
    main(sys.argv[1:])
