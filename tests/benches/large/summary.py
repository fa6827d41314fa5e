#!/usr/bin/env python3
"""Tables and a plot from the runs `large.sh` recorded.

    summary.py RUNS.tsv OUT.json OUT.png RUNS LOAD

RUNS.tsv: one line per run: input triangles, command, output triangles per input triangle,
wall s, user s, sys s, peak KiB, output bytes. Prints two Markdown tables (every command; g2tess
cost per input triangle by size), writes every figure as JSON, and plots microseconds per input
triangle against input triangles (log scale) for every command.
"""
import json
import os
import platform
import statistics
import sys


# The label of the fixed-cost runs (`large.sh`): not a command on the input.
START = "g2tess start-up"


def main():
    raw, out_json, out_png, runs, load = sys.argv[1:6]
    rows = {}
    for line in open(raw):
        size, label, factor, wall, user, sys_s, kib, out_bytes = line.rstrip("\n").split("\t")
        key = (int(size), label)
        r = rows.setdefault(key, {"factor": int(factor), "wall": [], "user": [], "sys": [],
                                  "kib": [], "bytes": int(out_bytes)})
        r["wall"].append(float(wall))
        r["user"].append(float(user))
        r["sys"].append(float(sys_s))
        r["kib"].append(int(kib))

    figures = []
    for (size, label), r in sorted(rows.items()):
        median = statistics.median(r["wall"])
        figures.append({
            "input_triangles": size,
            "command": label,
            "output_triangles": size * r["factor"],
            "runs": len(r["wall"]),
            "median_s": median,
            "min_s": min(r["wall"]),
            "max_s": max(r["wall"]),
            "worst_over_median": max(r["wall"]) / median if median > 0 else float("nan"),
            "median_user_s": statistics.median(r["user"]),
            "median_sys_s": statistics.median(r["sys"]),
            "peak_mib": max(r["kib"]) / 1024,
            "output_mib": r["bytes"] / 2**20,
            "us_per_input_triangle": median / size * 1e6,
        })
    by_key = {(f["input_triangles"], f["command"]): f for f in figures}

    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), "?")
    print(f"machine: {os.cpu_count()} cores, {cpu}, {platform.system()} {platform.release()}; "
          f"{runs} runs per command, rotated; load average before the run {load}")
    print()
    print("| input triangles | command | output triangles | median s | min–max s | worst/median "
          "| user s | sys s | peak MiB | peak / output bytes | µs per input triangle | × OpenSubdiv |")
    print("| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for f in figures:
        ratio = ""
        if f["command"] == START:
            print(f"| 20 (bundled icosahedron, in the {f['input_triangles']:,} rounds) | "
                  f"{f['command']} | 20 | {f['median_s']:.3f} | {f['min_s']:.3f}–{f['max_s']:.3f} | "
                  f"{f['worst_over_median']:.2f} | {f['median_user_s']:.2f} | "
                  f"{f['median_sys_s']:.2f} | {f['peak_mib']:.0f} | | | |")
            continue
        if f["command"].startswith("g2tess"):
            level = int(f["command"].split()[-1])
            loop = {2: 1, 4: 2}.get(level)
            peer = by_key.get((f["input_triangles"], f"OpenSubdiv Loop level {loop}"))
            if peer:
                ratio = f"{f['median_s'] / peer['median_s']:.2f}"
        print(f"| {f['input_triangles']:,} | {f['command']} | {f['output_triangles']:,} | "
              f"{f['median_s']:.3f} | {f['min_s']:.3f}–{f['max_s']:.3f} | "
              f"{f['worst_over_median']:.2f} | {f['median_user_s']:.2f} | {f['median_sys_s']:.2f} | "
              f"{f['peak_mib']:.0f} | {f['peak_mib'] / f['output_mib']:.2f} | "
              f"{f['us_per_input_triangle']:.3f} | {ratio} |")

    sizes = sorted({f["input_triangles"] for f in figures})
    ours = sorted({f["command"] for f in figures
                   if f["command"].startswith("g2tess") and f["command"] != START},
                  key=lambda c: int(c.split()[-1]))
    print()
    print("g2tess, µs of whole-process time per input triangle (median), and the largest over the "
          "smallest of each row:")
    print()
    print("| command | " + " | ".join(f"{s:,}" for s in sizes) + " | largest / smallest |")
    print("| --- | " + " | ".join("---:" for _ in sizes) + " | ---: |")
    for c in ours:
        cells = [by_key[(s, c)]["us_per_input_triangle"] for s in sizes if (s, c) in by_key]
        spread = max(cells) / min(cells) if cells else float("nan")
        print(f"| {c} | " + " | ".join(f"{x:.3f}" for x in cells) + f" | {spread:.2f} |")

    # The same without the fixed cost of a run (process start, reading and writing a 20-triangle
    # file), measured in the same rounds as each size: what each added input triangle costs.
    starts = {s: by_key[(s, START)]["median_s"] for s in sizes if (s, START) in by_key}
    if starts:
        print()
        print("The same without the fixed cost of a run (the start-up row of the same rounds, "
              "median " + ", ".join(f"{starts[s] * 1e3:.1f} ms" for s in sorted(starts)) + "):")
        print()
        print("| command | " + " | ".join(f"{s:,}" for s in sizes) + " | largest / smallest |")
        print("| --- | " + " | ".join("---:" for _ in sizes) + " | ---: |")
        for c in ours:
            cells = [(by_key[(s, c)]["median_s"] - starts.get(s, 0.0)) / s * 1e6
                     for s in sizes if (s, c) in by_key]
            for s in sizes:
                if (s, c) in by_key:
                    by_key[(s, c)]["us_per_input_triangle_without_start"] = (
                        (by_key[(s, c)]["median_s"] - starts.get(s, 0.0)) / s * 1e6)
            spread = max(cells) / min(cells) if cells else float("nan")
            print(f"| {c} | " + " | ".join(f"{x:.3f}" for x in cells) + f" | {spread:.2f} |")

    json.dump({"runs": int(runs), "load_before": float(load), "figures": figures},
              open(out_json, "w"), indent=1)
    plot(figures, out_png)


def plot(figures, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"(matplotlib missing: no plot written to {path})", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=110)
    commands = sorted({f["command"] for f in figures if f["command"] != START})
    for c in commands:
        points = sorted((f["input_triangles"], f["us_per_input_triangle"])
                        for f in figures if f["command"] == c)
        style = "-o" if c.startswith("g2tess") else "--s"
        ax.plot([p[0] for p in points], [p[1] for p in points], style, label=c, markersize=4)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("input triangles")
    ax.set_ylabel("µs per input triangle (median wall time)")
    ax.set_title("Whole-process cost per input triangle")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    print(f"plot: {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
