# The harness of the CLI test scripts (sourced): a scratch directory to work in, `expect CODE
# COMMAND...` that runs a command into out.txt/err.txt and checks its exit code, `fail MESSAGE`,
# and `finish WHAT` that reports and sets the exit status.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0

fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
expect() {
  local code=$1; shift
  "$@" > out.txt 2> err.txt
  local got=$?
  [[ $got == "$code" ]] || fail "'$*' exited $got, expected $code; stderr: $(head -c 300 err.txt)"
}
finish() {
  if ((failures)); then
    echo "$1: $failures failure(s)"
    exit 1
  fi
  echo "$1: all checks passed"
  exit 0
}
