"""The output folder of a run: where it may be, who uses it, and what an earlier run left.

* Where (:func:`check_output_dir`): never in a system folder (``/etc``, ``/usr``, ``/proc``,
  ... even as root); a folder named by a scene's ``[output] dir`` must lie under the scene's
  folder or the current folder (``beamfx run --out`` may name any other).
* Who (:class:`FolderLock`): a run holds ``.beamfx.lock`` (created with ``O_EXCL``: pid,
  host, start time, scene), so a second run into a busy folder is refused, naming the
  process; a lock whose process is gone (killed) is stale and taken over.
* What (:func:`clear_earlier_run`): a fresh run removes the files an earlier run wrote there
  (frames, series, probes, results, checkpoints, pictures; only names beamfx writes); a
  restart keeps them (the series and probes are cut back to the checkpoint by the analysis).
  An earlier run's frame files are left for the new frames of the same name to overwrite in
  place, and those the new run did not write are removed when it ends
  (:func:`remove_unwritten`): creating a file after its unlink cost 1-2 ms on the machine of
  the benchmarks, writing over it in place 13 µs (the spin-up writes 207 frames).
"""

import json
import os
import re
import socket
import time
from contextlib import contextmanager
from pathlib import Path

LOCK = ".beamfx.lock"
SYSTEM_FOLDERS = (
    "/bin", "/boot", "/dev", "/etc", "/lib", "/lib32", "/lib64", "/libx32", "/proc", "/run",
    "/sbin", "/sys", "/usr", "/var/cache", "/var/lib", "/var/log", "/var/mail", "/var/run",
    "/var/spool",
)  # fmt: skip
#: the files of a run (a fresh run removes them; see docs/scenes.md, "Files written in it")
RUN_FILES = re.compile(
    r"(results\.json|probes\.csv|probes\.jsonl|reactions\.csv|path\.csv|open_in_paraview\.py"
    r"|(deformed|surface)(_\d{4,}(_\d+)?\.(vtu|pvtu)|\.pvd|\.xdmf|\.h5)"
    r"|deformed\.(part\d+\.h5|before_restart\.(xdmf|h5))"
    r"|reactions(_\d{4,}\.vtu|\.pvd)"
    r"|undeformed\.vtu|deformed\.png|mode_\d+\.png|animation\.gif"
    r"|checkpoint_\d+ranks_\d+\.npz|\.checkpoint_\d+ranks_\d+\.\d+\.tmp\.npz|\.tmp-.*\.json)"
)

#: the frame files among them (:mod:`beamfx.io.series`), overwritten in place by a new run
FRAME_FILES = re.compile(r"(deformed|surface)_\d{4,}(_\d+)?\.(vtu|pvtu)|reactions_\d{4,}\.vtu")


class FolderError(OSError):
    """An output folder that may not or cannot be used now."""

    collective = True


_SYSTEM_PATHS = tuple(Path(s) for s in SYSTEM_FOLDERS)


def system_folder(path):
    """The system folder that ``path`` (resolved) is in, or None; ``/`` itself counts."""
    p = Path(path).resolve()
    if p == Path("/"):
        return "/"
    enclosing = {p, *p.parents}  # built once, not once per system folder
    for s, sp in zip(SYSTEM_FOLDERS, _SYSTEM_PATHS):
        if sp in enclosing:
            return s
    return None


def check_output_dir(path, scene_file=None):
    """Refuse an output folder in a system folder; with ``scene_file`` (the folder is the
    scene's ``[output] dir``) also one outside the scene's folder and the current folder.

    Raises:
        FolderError: naming the folder, the rule and the way out.
    """
    where = f"{scene_file}: output.dir: " if scene_file else "--out: "
    resolved = Path(path).resolve()
    system = system_folder(resolved)
    if system:
        raise FolderError(
            f"{where}{str(path)!r} is in the system folder {system}: beamfx writes no results "
            f"under {', '.join(('/',) + SYSTEM_FOLDERS)}"
        )
    if scene_file is None:
        return
    if str(path).startswith("~"):
        raise FolderError(
            f"{where}{str(path)!r}: '~' is not your home folder here (nothing in a scene is "
            "expanded); give a folder relative to the current one, or 'beamfx run --out'"
        )
    if not os.path.exists(scene_file):
        return
    roots = [Path.cwd().resolve(), Path(scene_file).resolve().parent]
    if resolved in roots:  # a fresh run would clear beamfx's file names there
        raise FolderError(
            f"{where}{str(path)!r} is the {'current' if resolved == roots[0] else 'scene'} "
            "folder itself: give a folder of its own below it (e.g. 'results'), or name it "
            "with 'beamfx run --out'"
        )
    if not any(r in resolved.parents for r in roots):
        raise FolderError(
            f"{where}{str(path)!r} ({resolved}) is outside the scene's folder ({roots[1]}) "
            f"and the current folder ({roots[0]}): a scene may only write under those; "
            "name another folder on the command line with 'beamfx run --out'"
        )


def _started(pid):
    """The start time of process ``pid`` (clock ticks since boot), or None if unknown."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as f:
            return int(f.read().rpartition(")")[2].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def _alive(owner):
    """Is the process that wrote lock ``owner`` still running (None: cannot tell)?"""
    if owner.get("host") != socket.gethostname():
        return None
    pid = owner.get("pid")
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    started = owner.get("started")
    return started is None or _started(pid) in (None, started)  # a reused pid is not it


def _describe(owner):
    since = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(owner.get("time", 0)))
    return (
        f"pid {owner.get('pid')} on {owner.get('host')}, since {since}, scene {owner.get('scene')}"
    )


def _take(path, scene):
    """Create the lock file ``path`` (O_EXCL) with this process's description; False if it
    exists."""
    me = {"pid": os.getpid(), "host": socket.gethostname(), "started": _started(os.getpid())}
    me.update(time=time.time(), scene=str(scene))
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        return False
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        json.dump(me, f)
    return True


def _owner(path):
    """The description in an existing lock (empty if unreadable: being written, or junk)."""
    try:
        owner = json.loads(Path(path).read_text(encoding="utf-8"))
        return owner if isinstance(owner, dict) else {}
    except (OSError, ValueError):
        return {}


def acquire(folder, scene, log=None):
    """Take ``folder``'s lock for this process (a stale one is taken over, said in ``log``).

    Raises:
        FolderError: if another running process holds it.
    """
    path = Path(folder) / LOCK
    for _ in range(3):
        if _take(path, scene):
            return path
        owner = _owner(path)
        age = time.time() - path.stat().st_mtime if path.exists() else 0.0
        alive = _alive(owner) if owner else age < 10.0  # junk: a lock being written
        if alive is False:
            if log:
                log(
                    f"note: {folder}: removed the stale lock of a run that ended ({_describe(owner)})"
                )
            path.unlink(missing_ok=True)
            continue
        who = _describe(owner) if owner else "a process that is starting"
        more = "" if alive else f"; if no run uses it, remove {path}"
        raise FolderError(
            f"{folder}: the output folder is in use by another beamfx run ({who}); wait for "
            f"it to end or choose another folder with --out{more}"
        )
    raise FolderError(f"{folder}: could not take the lock {path}")


def release(path):
    """Remove the lock at ``path`` if it is this process's."""
    if _owner(path).get("pid") == os.getpid():
        Path(path).unlink(missing_ok=True)


def clear_earlier_run(folder, restart):
    """Remove what an earlier run wrote in ``folder`` (only names beamfx writes, listed by
    :data:`RUN_FILES`); on a restart nothing (its ``results.json`` goes once the checkpoint
    is accepted: a refused restart leaves the folder as it was). A symbolic link with one of
    those names is removed in both cases (the link, not what it points to: a run never writes
    through a link, which could lead out of the folder). Frame files
    (:data:`FRAME_FILES`) are kept for the new run to overwrite in place, unless another name
    links to the same file (a copy made with ``cp -l`` would change with them): returns (the
    names removed, ``{frame file name: its stat signature}``) for :func:`remove_unwritten`."""
    folder = Path(folder)
    removed, frames = [], {}
    # one listing, whose entries know their type (no stat per name; a run's folder holds a
    # file per frame): beamfx's names only
    with os.scandir(folder) as listing:
        entries = sorted((e for e in listing if RUN_FILES.fullmatch(e.name)), key=_name)
    links = {e.name for e in entries if e.is_symlink()}
    for entry in entries:  # a link never written through: the link goes
        if entry.name in links:
            os.unlink(entry.path)
            removed.append(entry.name)
    for entry in entries:
        if restart or entry.name in links:
            continue
        if entry.is_file(follow_symlinks=False):
            st = entry.stat(follow_symlinks=False)
            if FRAME_FILES.fullmatch(entry.name) and st.st_nlink == 1:  # hard link: not in place
                frames[entry.name] = _signature(st)
                continue
            os.unlink(entry.path)
            removed.append(entry.name)
    return removed, frames


def _name(entry):
    return entry.name


def _signature(st):
    """What changes when a file is written again (of its ``os.stat``): inode, size and
    modification time."""
    return st.st_ino, st.st_size, st.st_mtime_ns


def remove_unwritten(folder, frames):
    """Remove the earlier run's frame files ``frames`` (from :func:`clear_earlier_run`) that
    this run did not write again (their stat signature is unchanged). Returns their names."""
    removed = []
    for name, signature in frames.items():
        path = Path(folder) / name
        try:
            if _signature(path.stat()) == signature:
                path.unlink()
                removed.append(name)
        except FileNotFoundError:
            pass
    return removed


@contextmanager
def claim(folder, comm, scene, restart=False, log=None):
    """Hold ``folder`` for one run: locked, cleared of an earlier run's files (rank 0), the
    lock released at the end. Collective: every rank raises the same :class:`FolderError`."""
    lock, error, frames = None, None, {}
    if comm.rank == 0:
        try:
            lock = acquire(folder, scene, log)
            removed, frames = clear_earlier_run(folder, restart)
            if (removed or frames) and log and not restart:
                log(
                    f"note: {folder}: removed {len(removed)} file(s) of an earlier run; its "
                    f"{len(frames)} frame file(s) are overwritten by this run's (the others "
                    "removed at its end)"
                )
        except OSError as e:
            error = str(e)
    error = comm.bcast(error, root=0) if comm.size > 1 else error
    if error:
        if lock:
            release(lock)
        raise FolderError(error)
    try:
        yield
        if frames or comm.size > 1:  # every rank's frames written before rank 0 looks
            comm.barrier()
        if frames:
            remove_unwritten(folder, frames)
    except BaseException as e:  # interrupted by a signal: say so in results.json
        from ..interrupt import interruption
        from .results import write_json_atomic

        signal = interruption(e)
        if signal is not None:
            stopped = {"scene": str(scene), "converged": False, "status": "stopped"}
            write_json_atomic(
                Path(folder) / "results.json", {**stopped, "reason": str(signal)}, comm
            )
        raise
    finally:
        if lock:
            release(lock)


__all__ = [
    "FolderError",
    "acquire",
    "check_output_dir",
    "claim",
    "clear_earlier_run",
    "release",
    "remove_unwritten",
    "system_folder",
]
