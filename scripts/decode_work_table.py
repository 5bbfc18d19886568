#!/usr/bin/env python3
"""Decode work of two amc builds side by side (docs/CODEC.md, "Decoding against issue 30's start").

Every hierarchy is encoded by each build with its own defaults (bit-exact, --quantize 12 and 16),
and each build decodes its own file with `amc info` (inspect plus a whole decode). Per file: the
exact sizes, the instructions callgrind counts (all threads; independent of the machine's load)
and the median CPU seconds (user + sys of the process) over ROUNDS runs, old and new alternating.

  scripts/decode_work_table.py [--rounds 7] [--no-callgrind] [--args "--hierarchy-contexts mixed"]
      [--new-args "--chunks 1"] OLD/amc NEW/amc -- corpus/*.amh
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

MODES = (("lossless", []), ("12 bits", ["--quantize", "12"]), ("16 bits", ["--quantize", "16"]))


def cpu_seconds(cmd):
    child = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    if status != 0:
        sys.exit(f"decode_work_table: {' '.join(cmd)} failed")
    return usage.ru_utime + usage.ru_stime


def instructions(cmd):
    run = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null"] + cmd,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=True)
    found = re.search(r"Collected : (\d+)", run.stderr)
    if not found:
        sys.exit(f"decode_work_table: no instruction count from callgrind for {' '.join(cmd)}")
    return int(found.group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--no-callgrind", action="store_true")
    parser.add_argument("--args", default="", help="extra encode options for both builds")
    parser.add_argument("--new-args", default="", help="extra encode options for the new build")
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("models", nargs="+", help="-- then .amh files")
    args = parser.parse_args()
    models = [m for m in args.models if m != "--"]
    callgrind = not args.no_callgrind and shutil.which("valgrind")
    builds = ((args.old, args.args.split()), (args.new, args.args.split() + args.new_args.split()))

    with tempfile.TemporaryDirectory() as out:
        files = []
        for model in models:
            name = os.path.basename(model)[:-len(".amh")] if model.endswith(".amh") else os.path.basename(model)
            for mode, options in MODES:
                pair = []
                for index, (amc, extra) in enumerate(builds):
                    path = os.path.join(out, f"{name}-{mode.split()[0]}-{index}.amc")
                    subprocess.run([amc, "-q", "-f", "encode", model, "-o", path] + options + extra, check=True)
                    pair.append(path)
                files.append((name, mode, pair))

        cpu = {id(f): ([], []) for f in files}
        for _ in range(args.rounds):
            for f in files:
                for index, (amc, _) in enumerate(builds):
                    cpu[id(f)][index].append(cpu_seconds([amc, "info", f[2][index]]))

        print("| model | coordinates | bytes old | bytes new | instructions old | instructions new | new / old |"
              " CPU ms old | CPU ms new | new / old (median of pairs) |")
        print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for f in files:
            name, mode, (old_file, new_file) = f
            sizes = [os.path.getsize(p) for p in (old_file, new_file)]
            if callgrind:
                counts = [instructions([amc, "info", p]) for (amc, _), p in zip(builds, (old_file, new_file))]
                ir = f"{counts[0] / 1e6:.1f} M | {counts[1] / 1e6:.1f} M | {counts[1] / counts[0]:.3f}"
            else:
                ir = "- | - | -"
            old_cpu, new_cpu = cpu[id(f)]
            pair_ratio = statistics.median(b / a for a, b in zip(old_cpu, new_cpu) if a > 0)
            print(f"| {name} | {mode} | {sizes[0]} | {sizes[1]} | {ir} | {1000 * statistics.median(old_cpu):.1f} |"
                  f" {1000 * statistics.median(new_cpu):.1f} | {pair_ratio:.3f} |")


if __name__ == "__main__":
    main()
