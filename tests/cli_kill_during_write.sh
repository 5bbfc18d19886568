#!/usr/bin/env bash
# A writer killed at any moment leaves the old file or the whole new one (write_file_atomically:
# temporary file, fsync, rename). `amc decode` and `amc encode` over an existing output are killed
# with SIGKILL at random points of their run, and half of the time right after their write starts
# (while the bytes are being written); each time the output must be byte for byte the
# old file or the complete new one. A killed writer may leave its temporary file (NAME.tmp.PID.N)
# beside the output, never anything else.
# Usage: cli_kill_during_write.sh AMC [TRIALS]
set -u
amc=$1
trials=${2:-10}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# A hierarchy whose leaf mesh is a few megabytes of OBJ, so that writing it takes a while.
"$amc" -q refine --model random --faces 100000 --seed 7 -o big.amh || { echo "FAIL: refine"; exit 1; }
"$amc" -q encode big.amh -o new.amc || { echo "FAIL: encode"; exit 1; }
"$amc" -q decode new.amc -o new.obj || { echo "FAIL: decode"; exit 1; }
"$amc" -q refine --model random --faces 2000 --seed 8 -o small.amh || exit 1
"$amc" -q encode small.amh -o old.amc || exit 1
"$amc" -q decode old.amc -o old.obj || exit 1

# Seconds a run takes, as a whole number of milliseconds.
run_ms() {
  local start end
  start=$(date +%s%N)
  "$@" > /dev/null 2>&1
  end=$(date +%s%N)
  echo $(((end - start) / 1000000))
}

old_kept=0
new_whole=0
killed_while_writing=0
# check_kill NAME OUTPUT COMMAND...: runs the command over the old OUTPUT, kills it, checks.
check_kill() {
  local name=$1 out=$2 total_ms=$3 trial=$4
  shift 4
  cp "old.${out##*.}" "$out"
  "$@" > /dev/null 2>&1 &
  local pid=$!
  if ((trial % 2 == 0)); then
    # A random point of the whole run (up to 20% past its usual end).
    local delay_ms=$((RANDOM % (total_ms + total_ms / 5 + 1)))
    sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
  else
    # Right after the write starts (a temporary file appears, or the output itself changes size,
    # as with a writer that is not atomic), or 1 to 4 ms later: inside the write.
    local old_size
    old_size=$(stat -c %s "$out")
    while kill -0 "$pid" 2> /dev/null && ! compgen -G "$out.tmp.*" > /dev/null &&
      [[ $(stat -c %s "$out" 2> /dev/null) == "$old_size" ]]; do :; done
    local delay_ms=$((RANDOM % 5))
    ((delay_ms > 0)) && sleep "0.00$delay_ms"
  fi
  kill -9 "$pid" 2> /dev/null
  wait "$pid" 2> /dev/null
  local temp
  temp=$(compgen -G "$out.tmp.*")
  [[ -n $temp ]] && killed_while_writing=$((killed_while_writing + 1))
  if cmp -s "$out" "old.${out##*.}"; then
    old_kept=$((old_kept + 1))
  elif cmp -s "$out" "new.${out##*.}"; then
    new_whole=$((new_whole + 1))
  else
    fail "$name, trial $trial: $out is neither the old file nor the new one ($(stat -c %s "$out") bytes)"
  fi
  # Nothing but the output, the temporary file and the fixtures.
  for f in *; do
    case $f in
      big.amh | small.amh | new.amc | new.obj | old.amc | old.obj | out.amc | out.obj | "$out".tmp.*) ;;
      *) fail "$name, trial $trial: unexpected file $f" ;;
    esac
  done
  rm -f "$out".tmp.*
}

decode_ms=$(run_ms "$amc" -q -f decode new.amc -o out.obj)
encode_ms=$(run_ms "$amc" -q -f encode big.amh -o out.amc)
rm -f out.obj out.amc
for ((trial = 0; trial < trials; ++trial)); do
  check_kill decode out.obj "$decode_ms" "$trial" "$amc" -q -f decode new.amc -o out.obj
  check_kill encode out.amc "$encode_ms" "$trial" "$amc" -q -f encode big.amh -o out.amc
done
# Under a heavy load the polling loop can miss a whole write; more kills at write start, bounded.
kills=$((2 * trials))
for ((extra = 0; killed_while_writing == 0 && extra < 20; ++extra)); do
  check_kill decode out.obj "$decode_ms" 1 "$amc" -q -f decode new.amc -o out.obj
  kills=$((kills + 1))
done
echo "$kills kills (decode ${decode_ms} ms, encode ${encode_ms} ms a run): old file kept $old_kept," \
  "new file whole $new_whole, killed while writing $killed_while_writing"
# The test must have hit the write itself, not only the computation before it.
((killed_while_writing > 0)) || fail "no kill landed while a temporary file existed"
((failures == 0)) && echo "all passed"
exit $((failures > 0))
