#!/usr/bin/env python3
"""One Pareto plot per scene from several harness CSVs (docs/multiple-scattering.md: every multiple-scattering
method of the SVS mapper, VTK's mapper and SVS with k_multi in one plot).

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        measurements/multiple-scattering-plots.py OUTPUT_DIR svs/trade.csv vtk/trade.csv ...

Writes OUTPUT_DIR/<scene>-pareto.png and OUTPUT_DIR/trade.csv (the rows together).
"""
import csv
import os
import sys

from nimbus import harness

NUMERIC = ("median_seconds", "rmse", "rmse_raw", "reference_noise", "relative_l1", "max_abs",
           "psnr_db", "precompute_seconds", "ms_mib")


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    output_dir, paths = argv[0], argv[1:]
    os.makedirs(output_dir, exist_ok=True)
    rows = []
    fields = None
    for path in paths:
        with open(path) as stream:
            reader = csv.DictReader(stream)
            fields = fields or reader.fieldnames
            rows.extend(reader)
    with open(os.path.join(output_dir, "trade.csv"), "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=fields, restval="")
        writer.writeheader()
        writer.writerows(rows)
    for row in rows:
        for key in NUMERIC:
            if row.get(key, "") != "":
                row[key] = float(row[key])
    for scene in sorted({row["scene"] for row in rows}):
        mine = [row for row in rows if row["scene"] == scene]
        path = os.path.join(output_dir, f"{scene}-pareto.png")
        harness.plot(mine, f"{scene}: error against time (reference: path tracer)", path)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
