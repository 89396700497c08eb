"""The benchmark assets' accuracy table of docs/ACCURACY.md ("The benchmark assets"), from the
reports bench/run leaves in OUT_DIR: each map's extraction report, its verify --truth report,
and that of its copy scaled by 0.8 (the negative control, which must fail).

    accuracy_table.py OUT_DIR COMMIT [--write DOC] ASSET...

Prints the Markdown table; --write also puts it into DOC between its "bench-accuracy-table"
markers.
"""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from write_between_markers import write_between_markers  # noqa: E402


def load(path):
    with open(path) as f:
        return json.load(f)


def row(out_dir, name, commit):
    report = load(os.path.join(out_dir, f"{name}-report-1.json"))
    truth = load(os.path.join(out_dir, f"{name}-verify-truth.json"))
    control = load(os.path.join(out_dir, f"{name}-verify-truth-x0.8.json"))
    t = truth["truth"]
    bound = t["bound"]
    tau = bound["tolerance"]
    local = bound.get("local_error", {})
    stats = report["statistics"]
    c = control["truth"]
    cells = [
        name,
        f"{stats['sculpt']['faces']:,}",
        report["method"]["used"],
        f"{tau:.3g}",
        f"{local.get('max', 0) / tau:.1f} / {local.get('rms', 0) / tau:.2f}",
        f"{bound['worst_ratio']:.2f}",
        f"{t['rms'] / tau:.2f}",
        f"{t['p99'] / tau:.2f}",
        "ok" if truth["passed"] else "**FAILED**",
        f"{c['rms'] / tau:.1f} / {c['p99'] / tau:.1f}",
        "fails" if not control["passed"] else "**passes**",
        f"{stats['texels']['written']:,}",
        commit,
    ]
    return "| " + " | ".join(cells) + " |"


def main(argv):
    write = None
    if "--write" in argv:
        i = argv.index("--write")
        write = argv[i + 1]
        del argv[i:i + 2]
    out_dir, commit, names = argv[1], argv[2], argv[3:]
    lines = [
        "| asset | sculpt quads | method | τ | e_v max / RMS (τ) | worst record / its bound "
        "| RMS (τ) | p99 (τ) | bounds | map × 0.8: RMS / p99 (τ) | × 0.8 | texels written "
        "| commit |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    lines += [row(out_dir, name, commit) for name in names]
    table = "\n".join(lines) + "\n"
    print(table, end="")
    if write:
        write_between_markers(write, "bench-accuracy-table", table)
        print(f"accuracy_table.py: the table written into {write}", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv)
