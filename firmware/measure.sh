#!/usr/bin/env bash
# The firmware's cost table (README): for E38, E56 and E76 on both boards,
# build with that variant's params file, read FLASH and RAM from the
# linker's size output (--print-memory-usage), run on QEMU (-icount
# shift=0) and read instructions_per_update and ram_bytes from the log.
# Then the running-gear example (gear-mps2-an386). Prints a Markdown
# table on stdout. Run from anywhere; needs what
# qemu-run.sh needs. Leaves the last build (E76) in target/.
set -euo pipefail
cd "$(dirname "$0")"

to_bytes() { # "19936 B" / "20 KB" -> bytes
  awk '{ m = 1; if ($2 == "KB") m = 1024; else if ($2 == "MB") m = 1048576; printf "%d", $1 * m }'
}

echo "| variant | board (core, number type) | instructions per update (mean / max) | estimator RAM, B | firmware flash, B | firmware RAM (static), B |"
echo "| --- | --- | --- | --- | --- | --- |"
for variant in E38 E56 E76; do
  for board in mps2-an386 lm3s6965evb; do
    case "$board" in
      mps2-an386)  target=thumbv7em-none-eabihf; desc="mps2-an386 (M4F, f32)" ;;
      lm3s6965evb) target=thumbv7m-none-eabi;    desc="lm3s6965evb (M3, I32F32)" ;;
    esac
    # Force a relink so the linker prints its size report.
    touch src/bin/"$board".rs
    build_log=$(TRACKBELT_PARAMS="../params/$variant.toml" \
      cargo build --release --bin "$board" --target "$target" 2>&1) || {
      echo "$build_log" >&2; echo "measure.sh: build failed ($variant, $board)" >&2; exit 1; }
    flash=$(echo "$build_log" | sed -n 's/.*FLASH: *\([0-9]* [KMG]*B\).*/\1/p' | head -1 | to_bytes)
    ram=$(echo "$build_log" | sed -n 's/.*RAM: *\([0-9]* [KMG]*B\).*/\1/p' | head -1 | to_bytes)
    run_log=$(./qemu-run.sh "target/$target/release/$board" --log-format '{s}' 2>&1) || {
      echo "$run_log" >&2; echo "measure.sh: run failed ($variant, $board)" >&2; exit 1; }
    grep -q "variant=$variant " <<<"$run_log" || { echo "measure.sh: $board did not run $variant" >&2; exit 1; }
    ipu=$(sed -n 's/.*instructions_per_update=\([0-9]*\).*/\1/p' <<<"$run_log")
    ipu_max=$(sed -n 's/.*instructions_per_update_max=\([0-9]*\).*/\1/p' <<<"$run_log")
    est_ram=$(sed -n 's/.*ram_bytes=\([0-9]*\).*/\1/p' <<<"$run_log")
    echo "| $variant | $desc | $ipu / $ipu_max | $est_ram | $flash | $ram |"
  done
done
# The running-gear example (feature gear, params/gear-4wheel.toml).
for board in gear-mps2-an386 gear-lm3s6965evb; do
  case "$board" in
    gear-mps2-an386)  target=thumbv7em-none-eabihf; desc="gear-mps2-an386 (M4F, f32, temperature input)" ;;
    gear-lm3s6965evb) target=thumbv7m-none-eabi;    desc="gear-lm3s6965evb (M3, I32F32, temperature input)" ;;
  esac
  touch src/bin/"$board".rs
  build_log=$(cargo build --release --features gear --bin "$board" --target "$target" 2>&1) || {
    echo "$build_log" >&2; echo "measure.sh: build failed ($board)" >&2; exit 1; }
  flash=$(echo "$build_log" | sed -n 's/.*FLASH: *\([0-9]* [KMG]*B\).*/\1/p' | head -1 | to_bytes)
  ram=$(echo "$build_log" | sed -n 's/.*RAM: *\([0-9]* [KMG]*B\).*/\1/p' | head -1 | to_bytes)
  run_log=$(./qemu-run.sh "target/$target/release/$board" --log-format '{s}' 2>&1) || {
    echo "$run_log" >&2; echo "measure.sh: run failed ($board)" >&2; exit 1; }
  ipu=$(sed -n 's/.*instructions_per_update=\([0-9]*\).*/\1/p' <<<"$run_log")
  ipu_max=$(sed -n 's/.*instructions_per_update_max=\([0-9]*\).*/\1/p' <<<"$run_log")
  est_ram=$(sed -n 's/.*ram_bytes=\([0-9]*\).*/\1/p' <<<"$run_log")
  table=$(sed -n 's/.*table_bytes=\([0-9]*\).*/\1/p' <<<"$run_log")
  echo "| gear (44 links, 4 wheels; table $table B) | $desc | $ipu / $ipu_max | $est_ram | $flash | $ram |"
done
