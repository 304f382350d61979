#!/usr/bin/env bash
# Renders one model's cubic (scenes/paper1994/NAME.toml) and quintic (NAME_quintic.toml)
# surfaces in the isophote, zebra and curvature modes and joins each pair with `apatch compare`'s
# difference: renders/quintic/NAME_{cubic,quintic}_MODE.png and NAME_MODE_cubic_vs_quintic.png.
# The quintic's curvature is drawn on the cubic's colour range (`--curvature-range`), so the two
# curvature panels share one scale.
# Usage: scripts/cubic_vs_quintic.sh NAME [MODE ...]   (run from the repository root)
set -euo pipefail
name=$1
shift
modes=("$@")
[ ${#modes[@]} -gt 0 ] || modes=(isophote zebra curvature)
bin=target/release/apatch
tmp=renders/tmp
out=renders/quintic
mkdir -p "$tmp" "$out"
cargo build --release --quiet
# The quintic is built once (heavy scenes take minutes: mpi_poly ~390 s) and each mode is
# rendered from its exported patches: the quintic's scene with its [model] and [scheme] tables
# replaced by `patches = …` (same camera, film, lights and render settings).
patches=$(pwd)/$tmp/${name}_quintic.json
qscene=$tmp/${name}_quintic_patches.toml
"$bin" export patches "scenes/paper1994/${name}_quintic.toml" --output "$patches" > /dev/null
{
  printf '[model]\npatches = "%s"\n\n' "$patches"
  awk '/^\[/ { skip = ($0 == "[model]" || $0 == "[scheme]") } !skip' "scenes/paper1994/${name}_quintic.toml"
} > "$qscene"
for mode in "${modes[@]}"; do
  cubic=$tmp/${name}_cubic_$mode.exr
  quintic=$tmp/${name}_quintic_$mode.exr
  log=$("$bin" render "scenes/paper1994/$name.toml" --mode "$mode" --output "$cubic" 2>&1)
  extra=()
  if [ "$mode" = curvature ]; then
    range=$(printf '%s\n' "$log" | sed -n 's/.*curvature colour range: ±\([0-9.e+-]*\).*/\1/p')
    extra=(--curvature-range "$range")
  fi
  "$bin" render "$qscene" --mode "$mode" --output "$quintic" "${extra[@]}" 2>&1 | tail -2
  cp "${cubic%.exr}.png" "$out/${name}_cubic_$mode.png"
  cp "${quintic%.exr}.png" "$out/${name}_quintic_$mode.png"
  "$bin" compare "$cubic" "$quintic" --side-by-side "$out/${name}_${mode}_cubic_vs_quintic.png" > /dev/null
done
