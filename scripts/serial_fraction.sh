#!/usr/bin/env bash
# What share of an encode and a decode runs outside the threads' tasks (docs/BENCHMARKS.md, "Threads
# and memory"): bench/chunks_bench repeats one operation on THREADS threads (default 2: a decode on
# one thread takes the chunks in order, without tasks) under `perf record` with call graphs; a
# sample is parallel work when its call chain passes through a parallel_for task
# (run_task, never inlined, names the task's lambda, which takes the task index:
# `{lambda(unsigned long)`, or `<lambda(size_t)>` in a frame perf unwinds as inlined from the
# debug info of a -g build), and serial otherwise. CPU-time samples: the shares do not depend on the machine's load. Amdahl's law
# then bounds the speed-up on T threads by 1 / (serial + (1 - serial) / T).
# Usage: scripts/serial_fraction.sh model.amh [build-dir] [runs]   (needs perf; BITS 0 and 12; THREADS=2)
# (BITS_LIST="12" or WHAT_LIST="encode" in the environment for fewer of them)
set -euo pipefail
model=$1
build=${2:-$(cd "$(dirname "$0")/.." && pwd)/build-bench}
runs=${3:-5}
threads=${THREADS:-2}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for bits in ${BITS_LIST:-0 12}; do
  for what in ${WHAT_LIST:-encode decode}; do
    perf record -q --call-graph=dwarf,16384 -F 999 -o "$tmp/perf.data" \
      "$build/bench/chunks_bench" repeat "$what" "$runs" "$threads" "$bits" "$model" > /dev/null 2>&1
    perf script -i "$tmp/perf.data" 2> /dev/null > "$tmp/perf.txt"
    python3 - "$tmp/perf.txt" "$what" "$bits" <<'PY'
import collections, re, sys
path, what, bits = sys.argv[1], sys.argv[2], sys.argv[3]
entry = "amc::" + what
samples = parallel = 0
serial = collections.Counter()
def name(frame):
    parts = frame.split(None, 1)
    return re.sub(r"\+0x[0-9a-f]+.*$", "", parts[1]) if len(parts) > 1 else ""
def is_task(symbol):
    return "{lambda(unsigned long)" in symbol or ("run_task<" in symbol and "<lambda(size_t)>" in symbol)
def short(symbol):
    return re.sub(r"\((?!anonymous).*", "", symbol).replace("(anonymous namespace)::", "")
def sample(stack):
    global samples, parallel
    names = [name(f) for f in stack]
    if any("warm_up_encode" in s for s in names):
        return  # chunks_bench's encode before the loop: its cold first pages are no step of the loop's
    top = next((i for i in range(len(names) - 1, -1, -1) if names[i] == entry or names[i].startswith(entry + "(")), None)
    if top is None:
        if any(is_task(s) for s in names):  # another thread's task
            samples += 1
            parallel += 1
        return  # else reading the model
    inner = names[:top]
    samples += 1
    if any(is_task(s) for s in inner):
        parallel += 1
    else:
        serial[" > ".join(short(s) for s in inner[max(0, len(inner) - 2):][::-1]) or "(itself)"] += 1
stack = []
for line in open(path, errors="replace"):
    if not line.strip():
        if stack: sample(stack)
        stack = []
    elif line[0] in " \t":
        stack.append(line.strip())
if stack: sample(stack)
share = 1 - parallel / max(samples, 1)
print(f"{what}, {bits} bits: {samples} samples, serial {100 * share:.1f} %: at most {1 / (share + (1 - share) / 2):.2f}x on 2 threads")
for stage, count in serial.most_common(6):
    print(f"    {100 * count / samples:5.1f} %  {stage}")
PY
  done
done
