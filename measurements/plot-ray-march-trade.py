#!/usr/bin/env python3
"""The speed <-> accuracy trade of the cloud mapper's two rendering methods beside VTK's
GPU ray caster, from the trade harness's CSVs of several runs (one run per renderer, since
the harness's --settings applies to one renderer only).

    python3 measurements/plot-ray-march-trade.py RUN1/trade.csv RUN2/trade.csv \
        --output-dir docs/ray-march [--title-note "..."]

Writes, in the output directory:
  trade.csv              the rows of every input, in input order (the harness's columns);
  trade-table.md         scene, renderer, setting, median time (s), RMSE, PSNR (dB), reference;
  <scene>-trade.png      per scene: median render time (s, log) against RMSE vs the reference
                         (linear radiance, log), one series per renderer and method (VTK's
                         GPU mapper; the cloud mapper by slices; by ray marching), each with
                         its Pareto front; the slices' points labelled with their number of
                         slices, the march's with its step in density texels;
  all-scenes-trade.png   every scene's points in one plot (no fronts: the scenes' errors
                         differ by more than the settings').
Needs only the standard library and matplotlib (no VTK, no display).
"""
import argparse
import csv
import json
import os
import sys

# A corrected RMSE of 0 (within the reference's noise) is drawn at this value.
RMSE_FLOOR = 1e-6

SERIES_STYLE = {  # name -> (colour, marker)
    "VTK GPU ray caster (vtk-gpu)": ("tab:gray", "s"),
    "cloud mapper, slices (svs; labels: slices)": ("tab:blue", "o"),
    "cloud mapper, ray march (svs method=march; labels: step in texels)": ("tab:red", "^"),
}


def read_rows(paths):
    rows = []
    fields = []
    for path in paths:
        with open(path, newline="") as stream:
            reader = csv.DictReader(stream)
            for name in reader.fieldnames:
                if name not in fields:
                    fields.append(name)
            rows.extend(reader)
    for row in rows:
        row["median_seconds"] = float(row["median_seconds"])
        row["rmse"] = float(row["rmse"])
        row["psnr_db"] = float(row["psnr_db"])
        row["settings"] = json.loads(row.get("settings_json") or "{}")
    return rows, fields


def series_name(row):
    if row["renderer"] == "vtk-gpu":
        return "VTK GPU ray caster (vtk-gpu)"
    if row["renderer"] == "svs":
        if row["settings"].get("method", "slices") == "march":
            return "cloud mapper, ray march (svs method=march; labels: step in texels)"
        return "cloud mapper, slices (svs; labels: slices)"
    return row["renderer"]


def point_label(row):
    settings = row["settings"]
    if row["renderer"] == "svs":
        if settings.get("method", "slices") == "march":
            return f"{settings.get('step', 2)}"
        return f"{settings.get('slices', 256)}"
    return ""


def pareto_front(rows):
    front = []
    for row in sorted(rows, key=lambda r: (r["median_seconds"], r["rmse"])):
        if not front or row["rmse"] < front[-1]["rmse"]:
            front.append(row)
    return front


def plot(rows, title, path, labels=True, fronts=True):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(8, 5.6), dpi=110)
    names = [name for name in SERIES_STYLE if any(series_name(r) == name for r in rows)]
    names += sorted({series_name(r) for r in rows} - set(names))
    for name in names:
        mine = [row for row in rows if series_name(row) == name]
        colour, marker = SERIES_STYLE.get(name, (None, "x"))
        x = [row["median_seconds"] for row in mine]
        y = [max(row["rmse"], RMSE_FLOOR) for row in mine]
        axis.scatter(x, y, label=name, s=28, color=colour, marker=marker, zorder=3)
        if labels:  # in order of time, above and below in turn (close points stay legible)
            ordered = sorted(zip(mine, x, y), key=lambda item: item[1])
            for k, (row, xi, yi) in enumerate(ordered):
                text = point_label(row)
                if text:
                    axis.annotate(text, (xi, yi), textcoords="offset points",
                                  xytext=(0, 7 if k % 2 == 0 else -12), ha="center",
                                  fontsize=7, color=colour)
        if not fronts:
            continue
        front = pareto_front(mine)
        axis.plot([row["median_seconds"] for row in front],
                  [max(row["rmse"], RMSE_FLOOR) for row in front], "-", linewidth=1,
                  color=colour)
    axis.set_xscale("log")
    axis.set_yscale("log")
    axis.set_xlabel("render time (s, median of the repeats; llvmpipe)")
    axis.set_ylabel("RMSE vs the path-traced reference (linear radiance)")
    axis.set_title(title, fontsize=10)
    axis.grid(True, which="both", linewidth=0.3)
    # Below the axes: inside, it would hide points.
    axis.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                frameon=False)
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)


def main(arguments):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csvs", nargs="+", help="trade.csv files of the harness")
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--title-note", default="",
                        help="text added to each plot's title")
    args = parser.parse_args(arguments)
    os.makedirs(args.output_dir, exist_ok=True)
    rows, fields = read_rows(args.csvs)
    scenes = []
    for row in rows:
        if row["scene"] not in scenes:
            scenes.append(row["scene"])

    with open(os.path.join(args.output_dir, "trade.csv"), "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=fields, restval="", extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({**row, "median_seconds": repr(row["median_seconds"]),
                             "rmse": repr(row["rmse"]), "psnr_db": repr(row["psnr_db"])})

    with open(os.path.join(args.output_dir, "trade-table.md"), "w") as stream:
        stream.write("| scene | renderer | setting | median time (s) | RMSE | PSNR (dB) | "
                     "reference |\n|---|---|---|---|---|---|---|\n")
        for scene in scenes:
            for row in rows:
                if row["scene"] == scene:
                    stream.write(f"| {row['scene']} | {row['renderer']} | {row['setting']} | "
                                 f"{row['median_seconds']:.3f} | {row['rmse']:.4g} | "
                                 f"{row['psnr_db']:.1f} | {row['reference']} |\n")

    note = f" {args.title_note}" if args.title_note else ""
    for scene in scenes:
        mine = [row for row in rows if row["scene"] == scene]
        references = ", ".join(sorted({row["reference"] for row in mine}))
        plot(mine, f"{scene} (reference: {references}){note}",
             os.path.join(args.output_dir, f"{scene}-trade.png"))
    plot(rows, f"all scenes (reference: path-traced){note}",
         os.path.join(args.output_dir, "all-scenes-trade.png"), labels=False, fronts=False)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
