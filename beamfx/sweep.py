"""Run a parameter sweep (a scene file with ``[[sweep]]`` tables) as an ensemble across ranks.

The ranks are split into groups (``MPI.Comm.Split``), as many as there are members up to one
per rank; member ``i`` is solved by group ``i mod groups`` on that group's communicator, so a
sweep of 8 load levels on ``mpirun -n 2`` solves two scenes at a time, one rank each, and a
sweep of 2 meshes on 4 ranks solves each mesh on 2 ranks. Each member writes its usual results
into ``member_NNN/`` under the sweep's folder; one line per finished member is appended to
``sweep.jsonl`` as it ends, and the whole table is written at the end as ``sweep.json``,
``sweep.csv`` and ``sweep.md``. A member whose solve fails is reported as failed (with the
solver's reason) and the others go on.
"""

import json
import os
import time
from functools import partial
from pathlib import Path


def groups_of(size, members):
    """(number of groups, group of each rank): contiguous blocks of ranks, sizes within one."""
    groups = max(1, min(size, members))
    return groups, [rank * groups // size for rank in range(size)]


def summary(run):
    """The numbers of one member's run (:class:`~beamfx.runner.RunResult`) that go into the
    sweep table: unknowns, iterations, probes, and what the analysis's ``summary()`` gives
    (frequencies, buckling factors, limit points, why it stopped)."""
    from .analyses.result import plain

    row = {
        "unknowns": run.model["unknowns"],
        "newton_iterations": run.result.newton_iterations,
        "probes": {
            name: {k: p[k] for k in ("displacement", "rotation_vector")}
            for name, p in run.probes.items()
        },
    }
    row.update(plain(run.result.summary()))
    return row


def _solve_member(member, folder, comm, log, run_scene, **options):
    from .scene import SceneError
    from .solvers import SolveFailed

    t0 = time.perf_counter()
    row = {"member": member.index, "values": member.values, "ranks": comm.size}
    try:
        results = run_scene(
            member.scene.file, folder, log=log, comm=comm, scene=member.scene, **options
        )
        row.update(status=results.result.status, **summary(results))
        if results.result.reason is not None:  # stopped before the end (sweep.md says why)
            row["reason"] = results.result.reason
    except (SolveFailed, SceneError, ValueError) as e:  # a member's values may clash (built
        # lazily), or its model be found too small for its settings once built (modes)
        row.update(status="failed", reason=str(e))
    row["wall_s"] = time.perf_counter() - t0
    row["folder"] = folder.name
    return row


def run_sweep(sweep, out_dir, run_scene, log=None, comm=None, **options):
    """Solve every member of ``sweep`` (:class:`beamfx.scene.Sweep`) on split communicators.

    Args:
        sweep: the parsed sweep.
        out_dir: the sweep's folder (None: the scene's ``[output] dir``).
        run_scene: the function that runs one member (:func:`beamfx.runner.run_scene`).
        log: message sink (rank 0 of ``comm``); each group's messages are prefixed.
        comm: the ranks to share out (default: all).
        options: passed to :func:`beamfx.runner.run_scene` (``png``, ``animate``, ``restart``).

    Returns:
        The sweep table as a dict (the same on every rank), also written as JSON/CSV/Markdown.
    """
    from mpi4py import MPI

    from .io import check_writable, write_json_atomic
    from .io import log as default_log
    from .io.folder import check_output_dir

    comm = comm or MPI.COMM_WORLD
    given, log = log, log or partial(default_log, comm=comm)
    out = Path(out_dir or sweep.output_dir)
    check_output_dir(out, sweep.file if out_dir is None else None)
    check_writable(out, comm)
    jsonl = out / "sweep.jsonl"
    if comm.rank == 0 and jsonl.exists():
        os.remove(jsonl)
    n = len(sweep.members)
    groups, color = groups_of(comm.size, n)
    group = comm.Split(color[comm.rank], comm.rank)
    log(
        f"sweep: {sweep.file}: {n} members over {', '.join(sweep.keys)}; "
        f"{comm.size} rank(s) in {groups} group(s) -> {out}/"
    )
    comm.Barrier()  # the stale sweep.jsonl is gone before any group appends
    t0 = time.perf_counter()
    rows = []
    for member in sweep.members[color[comm.rank] :: groups]:
        tag = f"[member {member.index}/{n}] "

        def member_log(msg, tag=tag):  # the caller's sink, else printed by the group's rank 0
            if given is None:
                default_log(tag + msg, comm=group)
            elif group.rank == 0:
                given(tag + msg)

        folder = out / f"member_{member.index:03d}"
        row = _solve_member(member, folder, group, member_log, run_scene, **options)
        rows.append(row)
        if group.rank == 0:
            with jsonl.open("a") as f:  # one short line, appended in a single write
                f.write(json.dumps(row) + "\n")
        member_log(f"{row['status']} in {row['wall_s']:.2f} s on {group.size} rank(s)")
    parts = comm.allgather(rows if group.rank == 0 else [])
    group.Free()
    rows = sorted((r for part in parts for r in part), key=lambda r: r["member"])
    table = {
        "scene": sweep.file,
        "keys": list(sweep.keys),
        "ranks": comm.size,
        "groups": groups,
        "wall_s": time.perf_counter() - t0,
        "members_wall_s": sum(r["wall_s"] for r in rows),
        "members": rows,
    }
    write_json_atomic(out / "sweep.json", table, comm)
    if comm.rank == 0:
        (out / "sweep.csv").write_text(to_csv(table))
        (out / "sweep.md").write_text(to_markdown(table))
    failed = [r["member"] for r in rows if r["status"] != "converged"]
    log(
        f"sweep: {n - len(failed)}/{n} members converged in {table['wall_s']:.2f} s "
        f"(members' own time {table['members_wall_s']:.2f} s); table in {out}/sweep.md"
        + (f"; failed: {failed}" if failed else "")
    )
    return table


def _columns(table):
    """(header, function of a row) for every column of the flat table."""
    cols = [("member", lambda r: r["member"])]
    cols += [(k, lambda r, k=k: json.dumps(r["values"][k])) for k in table["keys"]]
    cols += [
        ("status", lambda r: r["status"]),
        ("unknowns", lambda r: r.get("unknowns", "")),
        ("ranks", lambda r: r["ranks"]),
        ("newton_iterations", lambda r: r.get("newton_iterations", "")),
        ("wall_s", lambda r: f"{r['wall_s']:.3f}"),
    ]
    first = next((r for r in table["members"] if r["status"] == "converged"), None)
    for name in (first or {}).get("probes", {}):
        for what, short in (("displacement", "u"), ("rotation_vector", "phi")):
            cols += [
                (
                    f"{name}.{short}_{axis}",
                    lambda r, n=name, w=what, i=i: (
                        f"{r['probes'][n][w][i]:.10g}" if "probes" in r else ""
                    ),
                )
                for i, axis in enumerate("xyz")
            ]
    for key, short in (("frequencies_hz", "f"), ("load_factors", "lambda")):
        count = len((first or {}).get(key, [])[:6])
        cols += [
            (
                f"{short}{i + 1}",
                lambda r, k=key, i=i: f"{r[k][i]:.10g}" if len(r.get(k, [])) > i else "",
            )
            for i in range(count)
        ]
    return cols


def to_csv(table):
    """The sweep table as CSV: one row per member, values of swept keys as JSON."""
    import csv
    import io

    cols = _columns(table)
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow([c for c, _ in cols])
    for r in table["members"]:
        writer.writerow([f(r) for _, f in cols])
    return text.getvalue()


def to_markdown(table):
    """The sweep table as Markdown, with the run's ranks and times above it."""
    cols = _columns(table)
    lines = [
        f"# Sweep of {table['scene']}",
        "",
        (
            f"{len(table['members'])} members on {table['ranks']} rank(s) in "
            f"{table['groups']} group(s): {table['wall_s']:.2f} s wall, "
            f"{table['members_wall_s']:.2f} s summed over members. Each member's files are in "
            "its folder `member_NNN/`."
        ),
        "",
        "| " + " | ".join(c for c, _ in cols) + " |",
        "|" + "---|" * len(cols),
    ]
    lines += ["| " + " | ".join(str(f(r)) for _, f in cols) + " |" for r in table["members"]]
    failed = [r for r in table["members"] if r["status"] != "converged"]
    lines += [""] + [f"member {r['member']} {r['status']}: {r['reason']}" for r in failed]
    return "\n".join(lines) + "\n"
