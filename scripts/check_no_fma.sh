#!/bin/sh
# The codec library holds no fused multiply-add: an encoder and a decoder built differently (one
# with FMA, one without) must take the same floating-point decisions (src/common/exact_float.h).
# Meaningful in a build whose compiler may contract (CI's -march=native -ffp-contract=fast); in a
# baseline x86-64 build there is no FMA instruction to find. Prints the functions that hold one.
# Usage: scripts/check_no_fma.sh LIBRARY (libamcodec.a or libamcodec.so)
set -eu
library=$1
command -v objdump > /dev/null || { echo "check_no_fma: objdump (binutils) is missing" >&2; exit 1; }
[ -r "$library" ] || { echo "check_no_fma: cannot read $library" >&2; exit 1; }
# x86-64: vfmadd/vfmsub/vfnmadd/vfnmsub (scalar and packed); aarch64: fmadd/fmsub/fnmadd/fnmsub, fmla/fmls.
found=$(objdump -d --no-show-raw-insn -C "$library" |
        awk '/^[0-9a-f]+ <.*>:$/ { fn = $0 }
             /\t(vfn?m(add|sub)[0-9a-z]*|fn?m(add|sub)|fml[as])[ \t]/ { print fn }' | sort | uniq -c)
if [ -n "$found" ]; then
    echo "fused multiply-adds in $library (route each product through rounded(), exact_float.h):"
    echo "$found"
    exit 1
fi
echo "no fused multiply-add in $library"
