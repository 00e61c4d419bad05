#!/usr/bin/env bash
# The build's controller kernels on microcontrollers (docs/performance.md,
# section "Microcontrollers"), for whatever model the build has:
#  1. the single-precision set (prru_f_ik_jd, _inverse_terms, _eom_solve,
#     _dynamics of build/generated/prru_f_kernels.c) and the descriptor
#     (prru_mechanism.c) cross-compiled for a Cortex-M4F (FPv4-SP: single
#     precision only) and linked into a bare-metal firmware with
#     --gc-sections, so it holds only what the set calls; the double set
#     (prru_kernels.c) for a Cortex-M7 with a double-precision FPU
#     (FPv5-D16). Strict warnings, -Werror, no contraction (as the host);
#  2. arm-none-eabi-nm proves the M4 firmware has no software double
#     routine (__aeabi_d*, __aeabi_f2d, __adddf3, ...): on an M4 each would
#     be a silent emulation costing some 100 cycles per operation. The
#     pattern is shown to catch a firmware that does use one;
#  3. the M7 firmware runs under QEMU (mps2-an500) on the first state
#     (every output finite: the double set runs on its FPU); the M4
#     firmware under QEMU (mps2-an386) on states drawn as
#     test_float_kernels draws them (every fourth at rest, the others
#     moving, accelerating and loaded) and prints every output's bit
#     pattern; test_float_kernels --mcu holds them to that test's bound
#     (16 FLT_EPSILON c S_y) against the double kernels and against this
#     host's float kernels, and prints how many words agree bit for bit and
#     newlib's sinf, cosf, sqrtf, tanhf, acosf, atan2f against glibc's in
#     ulp over a sweep;
#  4. code size per kernel (nm -S of the linked firmware: the function with
#     its literal pool) within 16 bytes per arithmetic operation of the
#     header's count (PRRU_F_ARITH_*, PRRU_ARITH_*): the straight-line code
#     is one load/store-free FPU instruction per operation at best, 4 bytes
#     in Thumb-2, plus operand traffic; far above 16 means spills, inlined
#     library code or guards gone wrong. For the paper's model (the
#     header's sha256 is models/3prru_paper.json's) also the budgets:
#     float inverse_terms <= 6144 B, the float set with the descriptor
#     <= 24576 B.
# With four limbs the set's inverse_terms gives tau and J_d, not fd
# (fd = J_d^+ tau needs the runtime's QR): said in the output.
# Missing tools (Debian: gcc-arm-none-eabi, libnewlib-arm-none-eabi,
# qemu-system-arm) are reported as SKIPPED; with CI=true or
# PRRU_MCU_REQUIRE=1 they fail the test.
set -u

SRC=${PRRU_SOURCE_DIR:-$(cd "$(dirname "$0")/.." && pwd)}
BUILD=${PRRU_BUILD_DIR:?PRRU_BUILD_DIR: the build directory (ctest sets it)}
GEN=$BUILD/generated
CHECK=$BUILD/tests/test_float_kernels
NSTATE=64
SWEEP=1000 # points per range of the float-function sweep

missing=()
for tool in arm-none-eabi-gcc arm-none-eabi-nm arm-none-eabi-size qemu-system-arm timeout; do
  command -v "$tool" >/dev/null 2>&1 || missing+=("$tool")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "SKIPPED: not installed: ${missing[*]} (Debian: gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm)"
  if [ "${CI:-}" = true ] || [ "${PRRU_MCU_REQUIRE:-0}" = 1 ]; then
    echo "FAIL: CI=true or PRRU_MCU_REQUIRE=1: the microcontroller test must run"
    exit 1
  fi
  exit 0
fi
for f in prru_f_kernels.c prru_f_kernels.h prru_kernels.c; do
  [ -f "$GEN/$f" ] || { echo "FAIL: $GEN/$f missing (build the project first)"; exit 1; }
done
[ -x "$CHECK" ] || { echo "FAIL: $CHECK missing (build the project first)"; exit 1; }

work=$(mktemp -d "${TMPDIR:-/tmp}/prru-mcu.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT
fail=0
bad() { echo "FAIL: $*"; fail=1; }
# The descriptor a controller drops in: the generator's own types, sized
# for the model (the build's prru_mechanism.{h,c} take the library's
# descriptor type, sized for every model: --types prru_descriptor.h).
[ -n "${PRRU_MODEL:-}" ] || { echo "FAIL: PRRU_MODEL: the build's model file (ctest sets it)"; exit 1; }
mkdir "$work/dropin" &&
  "${PYTHON:-python3}" "$SRC/gen/prru_gen.py" "$PRRU_MODEL" --out "$work/dropin" --prefix prru --quiet ||
  { echo "FAIL: generating the drop-in descriptor of $PRRU_MODEL"; exit 1; }
cp "$work/dropin/prru_mechanism.c" "$work/dropin/prru_mechanism.h" "$work/"

COMMON=(-mthumb -mfloat-abi=hard -Os -ffp-contract=off -std=c99 -Wall -Wextra -Werror
        -ffunction-sections -fdata-sections)
M4=(-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 "${COMMON[@]}" -Wdouble-promotion -Wfloat-conversion)
M7=(-mcpu=cortex-m7 -mfpu=fpv5-d16 "${COMMON[@]}")
INC=(-I"$work" -I"$SRC/tests" -I"$SRC/tests/mcu" -I"$GEN")
# No C library start-up (tests/mcu/startup.c is the firmware's); newlib's
# libm and libc for sinf, memcpy; nosys for the few stubs libc names.
LINK=(-nostartfiles -T "$SRC/tests/mcu/mps2.ld" -Wl,--gc-sections --specs=nosys.specs)

cc_obj() { # out.o flags-array-name source
  local out=$1 arr=$2[@] src=$3
  if ! arm-none-eabi-gcc "${!arr}" "${INC[@]}" -c "$src" -o "$out" >"$out.log" 2>&1 || [ -s "$out.log" ]; then
    bad "compile $(basename "$src") for ${2}:"
    cat "$out.log"
    return 1
  fi
}

# ---- 1. build both firmwares ----
"$CHECK" --states "$NSTATE" "$work/mcu_states.h" || { echo "FAIL: test_float_kernels --states"; exit 1; }
echo "#define MCU_SWEEP $SWEEP" >>"$work/mcu_states.h"
ok=1
for s in fw_float startup; do cc_obj "$work/m4_$s.o" M4 "$SRC/tests/mcu/$s.c" || ok=0; done
cc_obj "$work/m4_kernels.o" M4 "$GEN/prru_f_kernels.c" || ok=0
cc_obj "$work/m4_mechanism.o" M4 "$work/prru_mechanism.c" || ok=0
for s in fw_double startup; do cc_obj "$work/m7_$s.o" M7 "$SRC/tests/mcu/$s.c" || ok=0; done
cc_obj "$work/m7_kernels.o" M7 "$GEN/prru_kernels.c" || ok=0
cc_obj "$work/m7_mechanism.o" M7 "$work/prru_mechanism.c" || ok=0
[ $ok = 1 ] || exit 1
arm-none-eabi-gcc "${M4[@]}" "${LINK[@]}" "$work"/m4_*.o -lm -o "$work/m4.elf" ||
  { echo "FAIL: link the M4 firmware"; exit 1; }
arm-none-eabi-gcc "${M7[@]}" "${LINK[@]}" "$work"/m7_*.o -lm -o "$work/m7.elf" ||
  { echo "FAIL: link the M7 firmware"; exit 1; }
echo "ok   built: Cortex-M4F float firmware, Cortex-M7 double firmware (-Os, -Werror)"

# ---- 2. no software double on the M4 ----
soft_double() { # elf: the software double-precision routines it holds
  arm-none-eabi-nm "$1" | awk '{print $NF}' |
    grep -E '^__aeabi_(d[a-z0-9]*|f2d|[a-z0-9]*2d)$|^__[a-z]*df[a-z]*[0-9]?$' | sort -u
}
printf 'double prod(double a, float b) { return a * b; }\n' >"$work/promote.c"
arm-none-eabi-gcc -mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mthumb -mfloat-abi=hard -Os -c "$work/promote.c" \
  -o "$work/promote.o" && arm-none-eabi-gcc -mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mthumb \
  -mfloat-abi=hard -nostdlib -Wl,--entry=prod "$work/promote.o" -lgcc -o "$work/promote.elf" ||
  bad "build the soft-double probe"
probe=$(soft_double "$work/promote.elf" | tr '\n' ' ')
case "$probe" in
  *__aeabi_dmul*__aeabi_f2d* | *__aeabi_f2d*__aeabi_dmul*) ;;
  *) bad "the soft-double pattern misses a firmware that multiplies doubles (found: '$probe')" ;;
esac
found=$(soft_double "$work/m4.elf")
if [ -n "$found" ]; then
  bad "the M4 float firmware calls software double routines:" $found
else
  echo "ok   nm: no software double routine in the M4 float firmware (a probe that multiplies doubles shows $(echo $probe | wc -w))"
fi

# ---- 3. run on the emulated Cortex-M4 ----
qrc=0
# The semihosting console into a file (without a terminal QEMU would
# send it to stderr, mixed with its own messages).
timeout 60 qemu-system-arm -M mps2-an386 -nographic -chardev file,id=sh,path="$work/m4.out" \
  -semihosting-config enable=on,target=native,chardev=sh -kernel "$work/m4.elf" \
  </dev/null >"$work/qemu.err" 2>&1 || qrc=$?
if [ $qrc -ne 0 ]; then
  bad "qemu-system-arm -M mps2-an386 exited $qrc (124: timeout)"
  head -c 2000 "$work/qemu.err"
  tail -n 3 "$work/m4.out"
fi
qrc=0
timeout 60 qemu-system-arm -M mps2-an500 -nographic -chardev file,id=sh,path="$work/m7.out" \
  -semihosting-config enable=on,target=native,chardev=sh -kernel "$work/m7.elf" \
  </dev/null >"$work/qemu7.err" 2>&1 || qrc=$?
if [ $qrc -ne 0 ]; then
  bad "qemu-system-arm -M mps2-an500 (the M7 double firmware) exited $qrc (124: timeout)"
  head -c 2000 "$work/qemu7.err" "$work/m7.out"
else
  echo "ok   QEMU mps2-an500 (Cortex-M7): $(cat "$work/m7.out")"
fi
echo "QEMU mps2-an386 (Cortex-M4F), $(grep -c '^S ' "$work/m4.out") states:"
"$CHECK" --mcu "$work/m4.out" || fail=1

# ---- 4. code size per kernel ----
sym_size() { # elf symbol: bytes (0 if absent)
  local hex
  hex=$(arm-none-eabi-nm -S "$1" | awk -v s="$2" '$4 == s { print $2; exit }')
  echo $((16#${hex:-0}))
}
arith() { # header macro
  awk -v m="$2" '$1 == "#define" && $2 == m { print $3 }' "$1"
}
obj_bytes() { # object: text + data (the descriptor is all read-only data)
  arm-none-eabi-size "$1" | awk 'NR == 2 { print $1 + $2 }'
}
paper_sha=$(sha256sum "$SRC/models/3prru_paper.json" | cut -d' ' -f1)
is_paper=0
grep -q "sha256 $paper_sha" "$GEN/prru_f_kernels.h" && is_paper=1
nact=$(arith "$GEN/prru_f_kernels.h" PRRU_F_NACT)
printf '%-14s %10s %6s %6s %12s %6s %6s\n' kernel "M4 float B" ops "B/op" "M7 double B" ops "B/op"
set_bytes=0
for k in ik_jd inverse_terms eom_solve dynamics; do
  K=$(echo "$k" | tr a-z A-Z)
  fb=$(sym_size "$work/m4.elf" "prru_f_$k")
  fo=$(arith "$GEN/prru_f_kernels.h" "PRRU_F_ARITH_$K")
  db=$(sym_size "$work/m7.elf" "prru_$k")
  do_=$(arith "$GEN/prru_kernels.h" "PRRU_ARITH_$K")
  printf '%-14s %10d %6d %6.1f %12d %6d %6.1f\n' "$k" "$fb" "$fo" "$(echo "$fb $fo" | awk '{print $1 / $2}')" \
    "$db" "$do_" "$(echo "$db $do_" | awk '{print $1 / $2}')"
  set_bytes=$((set_bytes + fb))
  [ "$fb" -gt 0 ] && [ "$db" -gt 0 ] || bad "prru_f_$k or prru_$k is not in its firmware"
  [ "$fb" -le $((16 * fo)) ] || bad "M4 float $k: $fb B for $fo operations, more than 16 B each"
  [ "$db" -le $((16 * do_)) ] || bad "M7 double $k: $db B for $do_ operations, more than 16 B each"
  [ "$k" = inverse_terms ] && it_bytes=$fb
done
desc=$(obj_bytes "$work/m4_mechanism.o")
set_bytes=$((set_bytes + desc))
libm=0
for f in sinf cosf sqrtf tanhf __kernel_sinf __kernel_cosf __ieee754_rem_pio2f __kernel_rem_pio2f \
         expm1f floorf scalbnf; do
  libm=$((libm + $(sym_size "$work/m4.elf" "$f")))
done
echo "descriptor prru_mechanism.o: $desc B; float set + descriptor: $set_bytes B;" \
     "newlib's float functions the firmware links: $libm B"
if [ "$nact" = 4 ]; then
  echo "four limbs: the float set's inverse_terms gives tau and J_d; fd = J_d^+ tau needs the runtime's QR" \
       "(the microcontroller set covers fd for three limbs, tau and J_d for four)"
fi
if [ $is_paper = 1 ]; then
  [ "$it_bytes" -le 6144 ] || bad "paper model: float inverse_terms $it_bytes B > 6144 B"
  [ "$set_bytes" -le 24576 ] || bad "paper model: float set + descriptor $set_bytes B > 24576 B"
  echo "paper model budgets: inverse_terms $it_bytes <= 6144 B, set + descriptor $set_bytes <= 24576 B"
fi
[ $fail = 0 ] && echo "ok   microcontroller builds, run and sizes"
exit $fail
