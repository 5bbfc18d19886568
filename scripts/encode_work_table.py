#!/usr/bin/env python3
"""Encode work of two one_core_speed builds side by side (docs/BENCHMARKS.md, "One-core encode").

Per model and BITS: each build's file size and FNV-1a hash (`one_core_speed encode 1 BITS MODEL`),
the instructions of the encode (callgrind, `encode 1` less `encode 0`, which only reads the
model; exact, independent of the machine's load), then PAIRS alternating rounds of whole
processes (`encode RUNS BITS MODEL` over every model, old and new in turn, the first build
alternating), each round's speed ratio new / old from the driver's median encode times and from
the processes' CPU time (os.wait4 rusage). Prints a Markdown table and the ratios' median [range].

  scripts/encode_work_table.py [--bits 12] [--pairs 5] [--runs 5] [--no-callgrind]
      OLD/bench/one_core_speed NEW/bench/one_core_speed -- corpus/*.amh
"""
import argparse
import os
import re
import statistics
import subprocess
import sys


def encode_line(binary, runs, bits, model):
    out = subprocess.run([binary, "encode", str(runs), str(bits), model], capture_output=True, text=True, check=True).stdout
    found = re.search(r"(\d+) bytes, FNV-1a ([0-9a-f]+); encode ([0-9.]+) \[", out)
    if not found:
        sys.exit(f"encode_work_table: no result from {binary} for {model}")
    return int(found.group(1)), found.group(2), float(found.group(3))


def instructions(binary, runs, bits, model):
    run = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", binary, "encode", str(runs),
                          str(bits), model], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=True)
    found = re.search(r"Collected : (\d+)", run.stderr)
    if not found:
        sys.exit(f"encode_work_table: no instruction count from callgrind for {binary} {model}")
    return int(found.group(1))


def timed_round(binary, runs, bits, models):
    """Sum over the models of the driver's median encode seconds per leaf, and the processes' CPU seconds."""
    driver = cpu = 0.0
    for model in models:
        child = subprocess.Popen([binary, "encode", str(runs), str(bits), model], stdout=subprocess.PIPE, text=True)
        out = child.stdout.read()
        _, status, usage = os.wait4(child.pid, 0)
        if status != 0:
            sys.exit(f"encode_work_table: {binary} failed on {model}")
        driver += 1.0 / float(re.search(r"encode ([0-9.]+) \[", out).group(1))
        cpu += usage.ru_utime + usage.ru_stime
    return driver, cpu


def summary(values):
    return f"{statistics.median(values):.3f} [{min(values):.3f}-{max(values):.3f}]"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bits", type=int, default=12)
    parser.add_argument("--pairs", type=int, default=5)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--no-callgrind", action="store_true")
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("models", nargs="+")
    args = parser.parse_args()
    builds = (args.old, args.new)
    print("| model | bytes old | bytes new | new / old | same bytes | instructions old | new | new / old |")
    print("|---|---:|---:|---:|:-:|---:|---:|---:|")
    total = [0, 0]
    for model in args.models:
        (size_old, hash_old, _), (size_new, hash_new, _) = (encode_line(b, 1, args.bits, model) for b in builds)
        row = f"| {os.path.basename(model)} | {size_old} | {size_new} | {size_new / size_old:.4f} | {'yes' if hash_old == hash_new else 'no'} |"
        if args.no_callgrind:
            print(row + " | | |")
            continue
        work = [instructions(b, 1, args.bits, model) - instructions(b, 0, args.bits, model) for b in builds]
        total = [t + w for t, w in zip(total, work)]
        print(row + f" {work[0] / 1e6:.1f} M | {work[1] / 1e6:.1f} M | {work[1] / work[0]:.3f} |")
    if not args.no_callgrind:
        print(f"| all | | | | | {total[0] / 1e6:.1f} M | {total[1] / 1e6:.1f} M | {total[1] / total[0]:.3f} |")
    driver_ratio, cpu_ratio, loads = [], [], []
    for p in range(args.pairs):
        order = (0, 1) if p % 2 == 0 else (1, 0)
        result = {}
        for i in order:
            result[i] = timed_round(builds[i], args.runs, args.bits, args.models)
        driver_ratio.append(result[0][0] / result[1][0])
        cpu_ratio.append(result[0][1] / result[1][1])
        loads.append(os.getloadavg()[0])
    if args.pairs > 0:
        print(f"\nspeed new / old over {args.pairs} alternating pairs (load average {min(loads):.1f}-{max(loads):.1f}): "
              f"driver's encode time {summary(driver_ratio)}, process CPU time {summary(cpu_ratio)}")


if __name__ == "__main__":
    main()
