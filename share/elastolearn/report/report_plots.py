#!/usr/bin/python3
"""Draw a learning report's plots (docs/report.md) with matplotlib.

Usage: report_plots.py REPORT_DATA_JSON PLOTS_DIR

Reads report_data.json (written by elastolearn's report writer, format
elastolearn-report-data/1) and writes a PNG per section it holds into PLOTS_DIR:
convergence.png, candidates.png, histograms.png, frame_errors.png,
correction_uniaxial.png, correction_scale.png, damping.png. The numbers are the
library's; this script only draws them. Each PNG is written to a temporary file
and renamed. Exit codes: 0 drawn, 2 bad input, 3 matplotlib missing.
"""
import json
import math
import os
import sys


def fail(code, message):
    print("report_plots.py: " + message, file=sys.stderr)
    sys.exit(code)


try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as e:  # the report writer shows this line on the page
    fail(3, "matplotlib is missing (%s): install python3-matplotlib" % e)


def save(fig, folder, name):
    path = os.path.join(folder, name)
    temporary = path + ".tmp.png"
    fig.savefig(temporary, dpi=100, bbox_inches="tight")
    plt.close(fig)
    os.replace(temporary, path)


def percent(values, size):
    return [None if v is None else 100.0 * v / size for v in values]


def masked(values):
    return [math.nan if v is None else v for v in values]


def shade_inside(ax, x, inside, label="training stretches"):
    """Shade the runs of x where inside is true."""
    start = None
    for i, flag in enumerate(list(inside) + [False]):
        if flag and start is None:
            start = i
        elif not flag and start is not None:
            ax.axvspan(x[start], x[i - 1], color="tab:green", alpha=0.12, lw=0, label=label)
            label = None
            start = None


def convergence(data, folder, size):
    c = data["convergence"]
    it = c["iteration"]
    loop = [i for i, f in enumerate(c["forward_fit"]) if not f]
    fit = [i for i, f in enumerate(c["forward_fit"]) if f]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
    for key, style, name in (("forward_rms_m", "o-", "rms"), ("forward_max_m", "s--", "max")):
        y = masked(percent(c[key], size))
        a.plot([it[i] for i in loop], [y[i] for i in loop], style, color="tab:blue", label=name + " (loop)")
        if fit:
            a.plot([it[i] for i in fit], [y[i] for i in fit], style, color="tab:orange", label=name + " (forward fit)")
    diverged = [it[i] for i, ok in enumerate(c["completed"]) if not ok]
    for k, x in enumerate(diverged):
        a.axvline(x, color="tab:red", alpha=0.3, label="diverged" if k == 0 else None)
    a.set_yscale("log")
    a.set_xlabel("iteration")
    a.set_ylabel("forward error [% of size]")
    a.set_title("forward error at the observed vertices")
    a.legend(fontsize=8)
    y = masked(c["control_force_rms_N"])
    b.plot(it, y, "o-", color="tab:purple")
    b.set_yscale("log")
    b.set_xlabel("iteration")
    b.set_ylabel("control force rms [N]")
    b.set_title("control-force norm")
    for ax in (a, b):
        ax.grid(True, which="both", alpha=0.3)
    save(fig, folder, "convergence.png")


def candidates(data, folder, size):
    rows = data["candidates"]["rows"]
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(rows) + 2), 3.8))
    labels = [r["label"] for r in rows]
    values = [math.nan if r["validation_rms_m"] is None else 100 * r["validation_rms_m"] / size for r in rows]
    colours = ["tab:green" if r["chosen"] else "tab:gray" for r in rows]
    ax.bar(range(len(rows)), [0 if math.isnan(v) else v for v in values], color=colours)
    for i, (v, r) in enumerate(zip(values, rows)):
        ax.text(i, v if not math.isnan(v) else 0, "diverged" if math.isnan(v) else ("chosen" if r["chosen"] else ""),
                ha="center", va="bottom", fontsize=8)
    ax.set_xticks(range(len(rows)), labels, rotation=30, ha="right")
    ax.set_yscale("log")
    ax.set_ylabel("validation error rms [% of size]")
    ax.set_title("held out: " + data["candidates"]["validation_data"], fontsize=10)
    ax.grid(True, axis="y", which="both", alpha=0.3)
    save(fig, folder, "candidates.png")


def histograms(data, folder, size):
    h = data["histograms"]
    edges = [100 * e / size for e in h["bin_edges_m"]]
    rows = [r for r in h["rows"] if r["completed"]]
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(9, 4))
    cmap = plt.get_cmap("viridis")
    for k, r in enumerate(rows):
        ax.stairs(r["counts"], edges, color=cmap(k / max(1, len(rows) - 1)), lw=1.6, label=r["label"])
    ax.set_xscale("log")
    ax.set_xlabel("vertex position error [% of size]")
    ax.set_ylabel("(frame, vertex) pairs")
    ax.set_title("error histogram per candidate: " + h["reference"], fontsize=10)
    ax.legend(fontsize=8, ncol=2)
    ax.grid(True, which="both", alpha=0.3)
    save(fig, folder, "histograms.png")


def frame_errors(data, folder, size):
    panels = data["frame_errors"]
    fig, axes = plt.subplots(1, len(panels), figsize=(6.5 * len(panels), 4), squeeze=False)
    for ax, p in zip(axes[0], panels):
        largest = 1e-12
        for m in p["models"]:
            # Frame 0 is the initial state, given to every model: its error is zero.
            t = [p["dt"] * i for i in range(1, len(m["max_m"]))]
            y = [max(v, 1e-12) for v in percent(m["max_m"][1:], size)]
            ax.plot(t, y, label=m["label"] + ("" if m["completed"] else " (stopped early)"))
            largest = max([largest] + y)
        # A motion that starts at rest has near-zero errors in its first frames: the axis shows
        # six decades below the largest error, not down to those.
        ax.set_ylim(bottom=1e-6 * largest)
        ax.set_yscale("log")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("max vertex error [% of size]")
        ax.set_title(p["title"] + "\nagainst " + p["reference"], fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    save(fig, folder, "frame_errors.png")


def correction(data, folder):
    c = data["correction"]
    u = c["uniaxial"]
    fig, ax = plt.subplots(figsize=(7.5, 4))
    shade_inside(ax, u["stretch"], u["inside"])
    ax.plot(u["stretch"], u["learned_axial"], color="tab:blue", label="learned, along the stretch")
    ax.plot(u["stretch"], u["learned_lateral"], color="tab:orange", label="learned, across it")
    if u["truth_axial"] is not None:
        ax.plot(u["stretch"], u["truth_axial"], "--", color="tab:blue", label="truth, along")
        ax.plot(u["stretch"], u["truth_lateral"], "--", color="tab:orange", label="truth, across")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("uniaxial stretch s   (F̂ = (s, 1, 1))")
    ax.set_ylabel("correction N [Pa]")
    ax.set_title("learned correction along uniaxial stretch")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    save(fig, folder, "correction_uniaxial.png")

    fig, ax = plt.subplots(figsize=(7.5, 4))
    colours = plt.get_cmap("tab10")
    for k, p in enumerate(c["deformation_scale"]):
        colour = colours(k)
        inside = [v if f else math.nan for v, f in zip(p["learned_norm"], p["inside"])]
        ax.plot(p["scale"], p["learned_norm"], color=colour, lw=1, alpha=0.6)
        ax.plot(p["scale"], inside, color=colour, lw=2.5, label=p["label"])
        if p["truth_norm"] is not None:
            ax.plot(p["scale"], p["truth_norm"], "--", color=colour, lw=1)
    ax.set_xlabel("deformation scale ‖F̂ − (1, 1, 1)‖")
    ax.set_ylabel("‖N‖ [Pa]")
    title = "learned correction (thick: within the training stretches)"
    if c["has_truth"]:
        title += "; dashed: truth"
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    save(fig, folder, "correction_scale.png")

    d = c["damping"]
    fig, ax = plt.subplots(figsize=(7.5, 4))
    shade_inside(ax, d["stretch"], d["inside"])
    ax.plot(d["stretch"], d["nominal_alpha1"], ":", color="k", label="nominal α₁")
    ax.plot(d["stretch"], d["learned_alpha1"], color="tab:blue", label="learned α₁ + Δα₁")
    if d["truth_alpha1"] is not None:
        ax.plot(d["stretch"], d["truth_alpha1"], "--", color="tab:red", label="truth α₁")
    ax.set_xlabel("largest stretch s₁   (F̂ = (s, 1, 1) above 1, (s, s, s) below)")
    ax.set_ylabel("stiffness damping α₁ [s]")
    ax.set_title("learned damping law")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    save(fig, folder, "damping.png")


def main():
    if len(sys.argv) != 3:
        fail(2, "usage: report_plots.py REPORT_DATA_JSON PLOTS_DIR")
    try:
        with open(sys.argv[1], encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        fail(2, "%s: %s" % (sys.argv[1], e))
    if data.get("format") != "elastolearn-report-data/1":
        fail(2, "%s: format: expected elastolearn-report-data/1" % sys.argv[1])
    folder = sys.argv[2]
    os.makedirs(folder, exist_ok=True)
    size = data["size_m"] if data.get("size_m", 0) > 0 else 1.0
    if data.get("convergence", {}).get("iteration"):
        convergence(data, folder, size)
    if data.get("candidates", {}).get("rows"):
        candidates(data, folder, size)
    if data.get("histograms", {}).get("rows"):
        histograms(data, folder, size)
    if data.get("frame_errors"):
        frame_errors(data, folder, size)
    if data.get("correction"):
        correction(data, folder)


if __name__ == "__main__":
    main()
