#!/usr/bin/env python3
"""Bar chart (SVG) of connectivity bits per face, per model and coder, from compare_bench's CSV.

Usage: scripts/bench_chart.py benchmarks.csv docs/images/benchmarks_connectivity.svg
Standard library only. The y axis is logarithmic: the coders span three orders of magnitude.
"""
import csv
import math
import sys
from xml.sax.saxutils import escape

# Coder id, legend label, colour: general-purpose coders in greys, Draco in blues, amcodec's
# hierarchy coders in warm colours.
CODERS = [
    ("zstd-19", "zstd -19 (raw indices)", "#bdbdbd"),
    ("xz-9", "xz -9 (raw indices)", "#969696"),
    ("meshopt", "meshopt index codec", "#737373"),
    ("meshopt+zstd", "meshopt + zstd -19", "#525252"),
    ("draco-default", "Draco default (speed 5)", "#9ecae1"),
    ("draco-best", "Draco best (speed 0)", "#2171b5"),
    ("naive-hierarchy", "naive hierarchy coder", "#fdd0a2"),
    ("amc-paper-naive", "paper, naive traversal", "#fd8d3c"),
    ("amc-paper-improved", "paper, improved traversal", "#d94801"),
    ("amc-best", "amcodec best", "#7f2704"),
]
LOW, HIGH = 0.0001, 100.0  # bits per face at the bottom and top of the axis (uniform: 0.0002)


def read_bits_per_face(path):
    """{model: {coder: bits per face}} for connectivity rows whose check passed, models in file order."""
    table = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["payload"] != "connectivity" or row["check"] != "ok":
                continue
            table.setdefault(row["model"], {})[row["coder"]] = float(row["bits_per_face"])
    return table


def draw(table, out_path):
    models = list(table)
    bar, group_gap = 7, 16
    group = bar * len(CODERS) + group_gap
    left, top, plot_h, bottom = 70, 70, 420, 130
    width = left + group * len(models) + 20
    height = top + plot_h + bottom

    def y_of(value):
        value = min(max(value, LOW), HIGH)
        return top + plot_h * (math.log10(HIGH) - math.log10(value)) / (math.log10(HIGH) - math.log10(LOW))

    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'font-family="sans-serif" font-size="12">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
        f'<text x="{left}" y="20" font-size="15" font-weight="bold">Connectivity: bits per face '
        f'(log scale), per model and coder; lower is better</text>',
    ]
    # Legend, two rows.
    per_row = (len(CODERS) + 1) // 2
    for i, (_, label, colour) in enumerate(CODERS):
        x = left + (i % per_row) * 200
        y = 34 + (i // per_row) * 16
        out.append(f'<rect x="{x}" y="{y}" width="11" height="11" fill="{colour}"/>')
        out.append(f'<text x="{x + 15}" y="{y + 10}">{escape(label)}</text>')
    # Grid lines at the decades.
    exponent = round(math.log10(LOW))
    while 10.0 ** exponent <= HIGH * 1.0001:
        value = 10.0 ** exponent
        y = y_of(value)
        out.append(f'<line x1="{left}" y1="{y:.1f}" x2="{width - 20}" y2="{y:.1f}" stroke="#dddddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{value:g}</text>')
        exponent += 1
    out.append(f'<text x="16" y="{top + plot_h / 2}" transform="rotate(-90 16 {top + plot_h / 2})" '
               f'text-anchor="middle">bits per face</text>')
    for m, model in enumerate(models):
        x0 = left + m * group + group_gap / 2
        for c, (coder, label, colour) in enumerate(CODERS):
            value = table[model].get(coder)
            if value is None:
                continue
            x = x0 + c * bar
            y = y_of(value)
            out.append(f'<rect x="{x:.1f}" y="{y:.1f}" width="{bar - 1}" height="{top + plot_h - y:.1f}" fill="{colour}">'
                       f'<title>{escape(model)}, {escape(label)}: {value:.3f} bits/face</title></rect>')
        label_x = x0 + bar * len(CODERS) / 2
        label_y = top + plot_h + 10
        out.append(f'<text x="{label_x:.1f}" y="{label_y}" transform="rotate(45 {label_x:.1f} {label_y})">'
                   f'{escape(model)}</text>')
    out.append(f'<line x1="{left}" y1="{top + plot_h}" x2="{width - 20}" y2="{top + plot_h}" stroke="black"/>')
    out.append("</svg>")
    with open(out_path, "w") as f:
        f.write("\n".join(out) + "\n")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    table = read_bits_per_face(sys.argv[1])
    if not table:
        sys.exit(f"{sys.argv[1]}: no connectivity results")
    draw(table, sys.argv[2])


if __name__ == "__main__":
    main()
