"""Campbell diagram: the rotating-frame frequencies over a list of speeds, each mode followed
from one speed to the next by its shape (modal assurance criterion), not by its rank.

Sorting by frequency swaps two branches where they cross (a flap and a lead-lag mode of a blade
do, since centrifugal stiffening raises flap faster); matching shapes keeps each branch.
"""

from typing import NamedTuple

import numpy as np

from .rotating import (
    assemble_mass,
    axis_fraction,
    mac_matrix,
    solve_rotating_modes,
    solve_steady,
)

#: a mode grows if Re λ exceeds this fraction of |λ| (the eigen solver's noise is ~1e-10)
GROWTH_TOL = 1e-6


class CampbellResult(NamedTuple):
    """A Campbell diagram: frequencies, branches and stability against the spin speed."""

    speeds: np.ndarray  # rad/s, the speeds reached (a failed steady state ends the sweep)
    frequencies_hz: np.ndarray  # (speeds, modes): per speed, lowest first
    branches_hz: np.ndarray  # (speeds, modes): branch b followed by shape from speed 0
    branches_growth: np.ndarray  # (speeds, modes): Re λ (1/s) along the branches
    mac: np.ndarray  # (speeds, modes): MAC of each branch's shape with its previous one
    out_of_plane: np.ndarray  # (speeds, modes): displacement share along the axis
    stable: np.ndarray  # (speeds,): no mode grows
    steady: tuple  # StaticResult per speed
    stopped_by: str | None  # why the sweep ended early (no steady state), else None
    failure: Exception | None = None  # a numerical failure that ended the sweep (SolveFailed)
    eigen_seconds: tuple = ()  # per speed: the eigen solve's compile, assemble and solve times


def track(previous, candidates, M):
    """Assign each previous shape to one candidate: the assignment of largest total MAC
    (Hungarian method). Returns (candidate index per previous shape, their MAC values)."""
    from scipy.optimize import linear_sum_assignment

    mac = mac_matrix(M, previous, candidates)
    rows, cols = linear_sum_assignment(-mac)
    order = np.empty(len(previous), dtype=int)
    order[rows] = cols
    return order, mac[np.arange(len(previous)), order]


def _follow(frame, shapes, modes, n_modes):
    """(order, MAC) of the branches among ``modes``: the first ``n_modes`` at the first
    speed (``shapes`` None), else tracked from ``shapes`` (:func:`track`)."""
    if shapes is None:
        return np.arange(n_modes), np.ones(n_modes)
    M = assemble_mass(frame)
    order, mac = track(shapes, modes.vectors, M)
    M.destroy()
    return order, mac


def campbell(
    frame,
    speeds,
    n_modes=6,
    steps=10,
    options=None,
    extra_modes=2,
    on_speed=None,
    log=None,
    continued=True,
):
    """Steady state and the ``n_modes`` lowest modes at each speed of ``speeds`` (rad/s), in
    the given order; branches start from the modes at the first speed, lowest first.

    ``extra_modes`` more modes are computed at each speed as candidates, so that a branch whose
    frequency rises past another one's is still found. A speed where no steady state is found
    (:func:`~beamfx.analyses.rotating.solve_steady`) ends the sweep; ``stopped_by`` says why.
    ``on_speed(i, speed)`` is called with the model at each steady state reached (i from 1).
    A numerical failure (Newton or an eigen solve) also ends it; ``failure`` holds it.
    ``continued``: each steady state starts from the previous speed's
    (:mod:`~beamfx.analyses.rotating_path`); else each is ramped from rest in ``steps``.
    The first one is always ramped from rest.
    """
    from ..solvers.snes import SolveFailed
    from .rotating_checks import NoSteadyState
    from .rotating_path import SpeedPath

    model = frame.model
    done, freq, b_hz, b_growth, b_mac, b_out, stable, steady = ([] for _ in range(8))
    shapes, stopped_by, failure, eigen = None, None, None, []
    path = SpeedPath() if continued else None
    for speed in speeds:
        try:
            steady.append(solve_steady(frame, speed, steps, options, path=path))
            if on_speed:
                on_speed(len(steady), speed)
            modes = solve_rotating_modes(frame, n_modes + extra_modes, options=options)
        except SolveFailed as e:
            if isinstance(e, NoSteadyState):
                stopped_by = str(e).splitlines()[0]
            else:
                failure = e
            if log:
                log(f"  {speed:.6g} rad/s: {str(e).splitlines()[0]}")
            steady = steady[: len(done)]
            break
        order, mac = _follow(frame, shapes, modes, n_modes)
        shapes = [modes.vectors[i] for i in order]
        eigen.append(modes.seconds)
        done.append(speed)
        freq.append(modes.hz[:n_modes])
        b_hz.append(modes.hz[order])
        b_growth.append(modes.growth[order])
        b_mac.append(mac)
        b_out.append([axis_fraction(model, v, frame.axis) for v in shapes])
        grows = modes.growth > GROWTH_TOL * np.abs(modes.eigenvalues)
        stable.append(not np.any(grows))
        if log:
            log(
                f"  {speed:.6g} rad/s: "
                + ", ".join(f"{f:.6g}" for f in modes.hz[:n_modes])
                + " Hz"
                + ("" if stable[-1] else " (unstable: a mode grows)")
            )
    return CampbellResult(
        np.array(done),
        np.array(freq),
        np.array(b_hz),
        np.array(b_growth),
        np.array(b_mac),
        np.array(b_out),
        np.array(stable, dtype=bool),
        tuple(steady),
        stopped_by,
        failure,
        tuple(eigen),
    )


def write_campbell(result, folder, comm=None):
    """``campbell.csv`` (speed, then one column per branch, Hz) and ``campbell.png`` in
    ``folder``, on rank 0."""
    from pathlib import Path

    from mpi4py import MPI

    if (comm or MPI.COMM_WORLD).rank != 0:
        return
    folder = Path(folder)
    n = result.branches_hz.shape[1] if result.branches_hz.ndim == 2 else 0
    head = ["speed_rad_s", "speed_rpm"] + [f"branch_{b + 1}_hz" for b in range(n)] + ["stable"]
    lines = [",".join(head)]
    for i, speed in enumerate(result.speeds):
        row = [f"{speed:.12g}", f"{speed * 30 / np.pi:.12g}"]
        row += [f"{f:.12g}" for f in result.branches_hz[i]] + [str(bool(result.stable[i]))]
        lines.append(",".join(row))
    (folder / "campbell.csv").write_text("\n".join(lines) + "\n")
    plot_campbell(result, folder / "campbell.png")


def plot_campbell(result, path):
    """Branches (Hz) against the speed (rad/s), with the 1P and 2P excitation lines; growing
    modes marked with a cross. Needs matplotlib (imported here)."""
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    with warnings.catch_warnings():  # "Unable to import Axes3D": Debian's mpl_toolkits is
        warnings.simplefilter("ignore", UserWarning)  # older than the venv's; no 3D needed
        import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    speeds = result.speeds
    for b in range(result.branches_hz.shape[1] if len(speeds) else 0):
        kind = "out of plane" if result.out_of_plane[0, b] > 0.5 else "in plane"
        style = "-" if kind == "out of plane" else "--"
        ax.plot(speeds, result.branches_hz[:, b], style, marker="o", ms=3, label=f"{b + 1}: {kind}")
        sigma = result.branches_growth[:, b]
        grows = sigma > GROWTH_TOL * np.hypot(2 * np.pi * result.branches_hz[:, b], sigma)
        if np.any(grows):
            ax.plot(speeds[grows], result.branches_hz[grows, b], "kx", ms=8)
    if len(speeds):
        top = float(np.max(result.branches_hz)) if result.branches_hz.size else 1.0
        for k in (1, 2):
            ax.plot(speeds, k * speeds / (2 * np.pi), ":", color="grey", lw=1)
            ax.annotate(f"{k}P", (speeds[-1], k * speeds[-1] / (2 * np.pi)), color="grey")
        ax.set_ylim(0, 1.1 * top)
    ax.set_xlabel("speed (rad/s)")
    ax.set_ylabel("frequency in the rotating frame (Hz)")
    ax.set_title("Campbell diagram (branches followed by MAC; x: growing mode)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
