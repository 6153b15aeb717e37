#!/usr/bin/env bash
# Cargo runner for the firmware (see .cargo/config.toml): runs an ELF on
# QEMU and decodes its defmt log. The QEMU machine is the binary's name
# (mps2-an386, lm3s6965evb); the binary must be built for that core:
#   mps2-an386  -> thumbv7em-none-eabihf (Cortex-M4F)
#   lm3s6965evb -> thumbv7m-none-eabi    (Cortex-M3)
#
# QEMU runs with -icount shift=0: one virtual nanosecond per instruction,
# deterministic, and idle time skipped (sleep=off), so the firmware's
# instruction counts are exact and four simulated seconds take well under
# a second. Exit status: the firmware's (0 pass, 1 fail), 124 on timeout.
#
# Usage: qemu-run.sh ELF [extra defmt-print args...]
# Env:   QEMU_TIMEOUT_S (default 60)
set -euo pipefail

elf=${1:?usage: qemu-run.sh ELF}
shift
board=$(basename "$elf")
# An example's binary is named <example>-<machine> (gear-mps2-an386).
case "$(basename "$elf")" in
  *-mps2-an386) board=mps2-an386 ;;
  *-lm3s6965evb) board=lm3s6965evb ;;
esac
case "$board" in
  mps2-an386)  machine=mps2-an386;  cpu=cortex-m4; target=thumbv7em-none-eabihf ;;
  lm3s6965evb) machine=lm3s6965evb; cpu=cortex-m3; target=thumbv7m-none-eabi ;;
  *) echo "qemu-run.sh: unknown board '$board' (binary name must be mps2-an386 or lm3s6965evb)" >&2; exit 2 ;;
esac
case "$elf" in
  */"$target"/*) ;;
  *) echo "qemu-run.sh: $board must be built with --target $target (try: cargo $board)" >&2; exit 2 ;;
esac
for tool in qemu-system-arm defmt-print; do
  if ! command -v "$tool" >/dev/null; then
    case "$tool" in
      qemu-system-arm) hint="apt-get install qemu-system-arm" ;;
      defmt-print) hint="cargo install defmt-print --locked" ;;
    esac
    echo "qemu-run.sh: $tool not found ($hint)" >&2
    exit 127
  fi
done

timeout "${QEMU_TIMEOUT_S:-60}" qemu-system-arm \
  -machine "$machine" -cpu "$cpu" \
  -nographic -monitor none -serial none \
  -semihosting-config enable=on,target=native \
  -icount shift=0,align=off,sleep=off \
  -kernel "$elf" \
  | defmt-print -e "$elf" "$@"
