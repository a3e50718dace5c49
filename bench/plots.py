"""The PNGs of `make bench` (bench/report.py calls these): box plots of the Table 3
runs, per configuration and per program, and the latency histograms side by side."""
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def box_png(path, title, groups):
    """groups: [(subplot title, [(label, values ms)])]"""
    fig, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 3.6), squeeze=False)
    for ax, (sub, boxes) in zip(axes[0], groups):
        boxes = [(n, v) for n, v in boxes if v]
        if boxes:
            ax.boxplot([v for _, v in boxes], showfliers=True)
            ax.set_xticks(range(1, len(boxes) + 1))
            ax.set_xticklabels([n for n, _ in boxes], rotation=0, fontsize=8)
        ax.set_title(sub, fontsize=9)
        ax.set_ylabel("ms")
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def overview_png(path, title, boxes):
    """boxes: [(configuration, run times ms)], one box each on a log axis."""
    fig, ax = plt.subplots(figsize=(11, 4.2))
    ax.boxplot([v for _, v in boxes], showfliers=True)
    ax.set_xticks(range(1, len(boxes) + 1))
    ax.set_xticklabels([n for n, _ in boxes], rotation=30, fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("ms (log), thread creation included")
    ax.set_title(title, fontsize=10)
    ax.grid(axis="y", alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def latency_png(path, sets):
    """sets: [(title, res)]: one row per place, cyclictest and ncpar side by side."""
    sets = [(t, r) for t, r in sets if r.get("cyclictest") or r.get("ncpar")]
    if not sets:
        return False
    fig, axes = plt.subplots(len(sets), 2, figsize=(11, 3.4 * len(sets)), squeeze=False)
    for row, (title, res) in zip(axes, sets):
        for ax, key in zip(row, ("cyclictest", "ncpar")):
            r = res.get(key) or {}
            h = r.get("hist") or []
            if h:
                ax.bar(range(len(h)), h, width=1.0)
                if r.get("overflow"):
                    ax.bar([len(h) + 5], [r["overflow"]], width=8.0, color="red",
                           label=">= %d us: %d" % (len(h), r["overflow"]))
                    ax.legend(fontsize=8)
                ax.set_yscale("log")
                ax.set_xlim(0, len(h) + 12)     # the same axis for every panel
            ax.set_title("%s - %s" % ("cyclictest" if key == "cyclictest"
                                      else "ncpar position loop", title), fontsize=9)
            ax.set_xlabel("wake-up latency (us, 1 us bins)")
            ax.set_ylabel("cycles (log)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True
