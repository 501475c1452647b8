"""Plots of the validation report (matplotlib, Agg): one figure per case, one summary.

Per case (``<case id>.png``), side by side: the error against the unknowns (log-log, one line
per element degree; a transient's unknowns are multiplied by its time steps, so that halving
dt moves a point too) and against the warm wall time, the tolerance dashed; then, where the
case keeps it, a third panel: the time history of a transient (``history``, finest setting),
the Campbell diagram of a rotating case (``extra["campbell"]``), or the load–displacement path
of a static case with load steps (``path``, finest setting). The summary (``summary.png``)
puts every case at its cheapest setting within tolerance: error / tolerance against warm wall
time.

matplotlib is imported where used: :func:`write_plots` raises ImportError without it.
"""

import re
from pathlib import Path

import numpy as np

PANEL = (5.0, 4.0)  # inches per panel
DPI = 100


def write_plots(results, folder):
    """Write the figures of ``results`` (of :func:`beamfx.bench.run.run_case`) into
    ``folder``; returns ``{case id or "summary": file name}``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(folder)
    figures = {}
    for r in results:
        name = f"{r['id']}.png"
        fig = case_figure(plt, r)
        fig.savefig(folder / name, dpi=DPI)
        plt.close(fig)
        figures[r["id"]] = name
    if results:
        fig = summary_figure(plt, results)
        fig.savefig(folder / "summary.png", dpi=DPI)
        plt.close(fig)
        figures["summary"] = "summary.png"
    return figures


def families(rows):
    """Rows grouped by element degree: ``{label: rows}``, coarse to fine."""
    out = {}
    for row in rows:
        out.setdefault(row["degree"], []).append(row)
    labelled = {}
    for p, group in out.items():
        dts = sorted({row["dt"] for row in group if "dt" in row})
        if len(dts) > 1:
            label = f"P{p}, dt {max(dts):g} → {min(dts):g} s"
        elif dts:
            label = f"P{p}, dt = {dts[0]:g} s"
        else:
            label = f"P{p}"
        labelled[label] = group
    return labelled


def _size(row):
    return row["unknowns"] * (row["load_steps"] if "dt" in row else 1)


def _error_panel(ax, r, x, xlabel):
    """Error against ``x(row)`` per family, log-log, with the tolerance."""
    shown = 0
    for label, group in families(r["rows"]).items():
        pts = [(x(row), row["error"]) for row in group if row["error"] > 0]
        if pts:
            ax.loglog(*zip(*pts), "o-", label=label, ms=4)
            shown += len(pts)
    ax.axhline(r["tolerance"], color="tab:red", ls="--", lw=1, label="tolerance")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("error" + ("" if r["error_scale"] == "relative" else " (absolute / scale)"))
    _major_labels_only(ax)
    ax.grid(True, which="both", alpha=0.3)
    if not shown:
        ax.text(0.5, 0.5, "all errors are 0", transform=ax.transAxes, ha="center")
    ax.legend(fontsize=8)


def _major_labels_only(ax):
    """Labels at minor log ticks only on an axis shorter than two decades, and then only
    at 2 and 5 (matplotlib's default labels crowd when a decade is short)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if lo > 0 and np.log10(hi / lo) < 2:
            axis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
            axis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        else:
            axis.set_minor_formatter(NullFormatter())


def case_figure(plt, r):
    """The figure of one case result (see the module docstring)."""
    extra = _extra_panel(r)
    fig, axes = plt.subplots(1, 2 + bool(extra), figsize=(PANEL[0] * (2 + bool(extra)), PANEL[1]))
    transient = any("dt" in row for row in r["rows"])
    _error_panel(
        axes[0], r, _size, "unknowns × time steps" if transient else "unknowns (degrees of freedom)"
    )
    axes[0].set_title("convergence")
    _error_panel(axes[1], r, lambda row: row["wall_s_warm"], "warm wall time (s)")
    axes[1].set_title("error against cost")
    if extra:
        extra(axes[2], r)
    finest = " (the finest setting is the reference, not shown)"
    fig.suptitle(f"{r['id']}: {r['title']}" + (finest if r["reference_is_finest_setting"] else ""))
    fig.tight_layout()
    return fig


def _extra_panel(r):
    if "history" in r:
        return history_panel
    if "campbell" in r.get("extra", {}):
        return campbell_panel
    if "path" in r:
        return path_panel
    return None


def _unit(label):
    m = re.search(r"\(([^)]*)\)\s*$", label)
    return m.group(1) if m else ""


def history_panel(ax, r):
    """The finest setting's time series; a second unit goes on a right-hand axis."""
    series = dict(r["history"])
    t = series.pop("t (s)")
    units = list(dict.fromkeys(_unit(k) for k in series))
    axes = [ax] + ([ax.twinx()] if len(units) > 1 else [])
    colours = iter(plt_colours())
    for label, values in series.items():
        side = axes[min(units.index(_unit(label)), len(axes) - 1)]
        side.plot(t, values, label=label, color=next(colours), lw=1.2)
    for side, unit in zip(axes, units):
        side.set_ylabel(", ".join(k for k in series if _unit(k) == unit))
    ax.set_xlabel("time t (s)")
    ax.grid(True, alpha=0.3)
    handles = [h for side in axes for h in side.get_legend_handles_labels()[0]]
    ax.legend(handles, [h.get_label() for h in handles], fontsize=8)
    ax.set_title("time history (finest setting)")


def plt_colours():
    """Matplotlib's ten default colours, in cycle order."""
    return [f"C{i}" for i in range(10)]


def campbell_panel(ax, r):
    """Frequencies against spin speed Ω (log-log), the finest setting and the paper's BEAM."""
    c = r["extra"]["campbell"]
    values = r["rows"][-1]["values"]
    scale = {"flap": c["omega_By"], "lead_lag": c["omega_Bz"]}
    for i, (branch, omega0) in enumerate(scale.items()):
        pts = []
        for key, ratio in values.items():
            name, _, alpha = key.partition(" alpha=")
            if name == branch and float(alpha) > 0:
                pts.append((float(alpha) * c["omega_By"], ratio * omega0 / (2 * np.pi)))
        if pts:
            ax.loglog(*zip(*sorted(pts)), "o-", ms=4, color=f"C{i}", label=f"{branch} (beamfx)")
        paper = [
            (a * c["omega_By"], v * omega0 / (2 * np.pi))
            for a, v in zip(c["alphas"], c[f"paper_{branch}"])
            if a > 0
        ]
        ax.loglog(*zip(*paper), "x", ms=7, color=f"C{i}", label=f"{branch} (paper, BEAM 32 el.)")
    spin = np.array(ax.get_xlim())
    ax.loglog(spin, spin / (2 * np.pi), "k:", lw=1, label="1 × Ω")
    ax.set_xlabel("spin speed Ω (rad/s)")
    ax.set_ylabel("first frequency in the rotating frame (Hz)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Campbell diagram (finest setting)")


def path_panel(ax, r):
    """Load factor against each measured value along the finest setting's load steps."""
    lam = [p["load_factor"] for p in r["path"]]
    for i, key in enumerate(k for k in r["path"][0] if k != "load_factor"):
        ax.plot([p[key] for p in r["path"]], lam, "o-", ms=3, color=f"C{i}", label=key)
        if key in r["reference"] and np.isclose(lam[-1], 1.0):
            label = "reference" if i == 0 else None
            ax.plot(r["reference"][key], 1.0, "k*", ms=9, label=label)
    ax.set_xlabel("tip value (the case's units: lengths, angles in rad)")
    ax.set_ylabel("load factor λ")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("load–displacement path (finest setting)")


def summary_figure(plt, results):
    """Every case at its cheapest setting within tolerance (or, failing that, its finest):
    error / tolerance against warm wall time."""
    fig, ax = plt.subplots(figsize=(10, 6.5))
    for r in results:
        row = r["cheapest_within_tolerance"] or r["rows"][-1]
        err = max(row["error"] / r["tolerance"], 1e-4)  # an exact answer sits on the floor
        ok = r["cheapest_within_tolerance"] is not None
        ax.loglog(row["wall_s_warm"], err, "o" if ok else "X", color="C0" if ok else "C3")
        ax.annotate(
            r["id"],
            (row["wall_s_warm"], err),
            fontsize=7,
            xytext=(4, 2),
            textcoords="offset points",
        )
    ax.axhline(1.0, color="tab:red", ls="--", lw=1, label="tolerance")
    ax.set_xlabel("warm wall time (s)")
    ax.set_ylabel("error / tolerance")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(
        "every case at its cheapest setting within tolerance (red X: none within; 1e-4: exact)"
    )
    fig.tight_layout()
    return fig
